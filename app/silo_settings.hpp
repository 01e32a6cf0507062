// The silo case's settings from `demcal silo`'s own options, for commands that run the silo case themselves
// (demcal cutoff --silo): the same options, defaults, checks and messages as `demcal silo` (cmd_silo.cpp).
#pragma once
#include <string>
#include <vector>

#include "kernel/silo/silo_case.hpp"

namespace demcal {

/// `options` as `demcal silo` takes them (e.g. {"--material", "meal.json", "--theta", "30"}); `owner` names the
/// command in messages. Throws UserError naming the option and value; options that set a run's own outputs or
/// sessions (--out, --vtk, --export-bed, --checkpoint-every, --wall-limit, --resume, ...) are refused.
kernel::silo::SiloCaseSettings silo_case_settings(const std::vector<std::string>& options, const std::string& owner);

}  // namespace demcal
