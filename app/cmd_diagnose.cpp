#include "app/commands.hpp"

namespace demcal {
void add_discharge_commands(CLI::App&) {}  // placeholder until the subcommand lands
}  // namespace demcal
