#include "app/commands.hpp"

namespace demcal {
void add_silo_command(CLI::App&) {}  // placeholder until the subcommand lands
}  // namespace demcal
