// The driver in 3D (core/simulation_impl.hpp).
#include "core/simulation_impl.hpp"

namespace sph {

template class SimulationT<3>;

}  // namespace sph
