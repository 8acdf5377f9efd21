// The driver in 2D (core/simulation_impl.hpp).
#include "core/simulation_impl.hpp"

namespace sph {

template class SimulationT<2>;

}  // namespace sph
