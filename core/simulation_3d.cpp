// The driver in 3D (core/simulation_impl.hpp).
#include "core/simulation_impl.hpp"

namespace sph {

template class SimulationT<3>;
template std::unique_ptr<SweepBase<3>> make_sweep<3>(const SolverSettingsT<3>&);

}  // namespace sph
