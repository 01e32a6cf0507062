// The contact laws the kernel is compiled with. A new law: an alias in contact/ (or a new sub-model file) and one
// line here.
#include "kernel/simulation_impl.hpp"

namespace demcal::kernel {
template class BasicSimulation<HertzMindlinEdem>;
template class BasicSimulation<HertzMindlin>;
template class BasicSimulation<JkrMindlinEdem>;
template class BasicSimulation<YadeCohesiveFrictional>;
template class BasicSimulation<YadeHertzMindlin>;
}  // namespace demcal::kernel
