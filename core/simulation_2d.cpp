// The driver in 2D (core/simulation_impl.hpp).
#include "core/simulation_impl.hpp"

namespace sph {

template class SimulationT<2>;
template std::unique_ptr<SweepBase<2>> make_sweep<2>(const SolverSettingsT<2>&);

}  // namespace sph
