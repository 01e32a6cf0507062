// The silo case's settings from `demcal silo`'s own options, for commands that run the silo case themselves
// (demcal cutoff --silo): the same options, defaults, checks and messages as `demcal silo` (cmd_silo.cpp).
#pragma once
#include <array>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "kernel/silo/silo_case.hpp"

namespace demcal {

/// The silo options that name an input file: a campaign records their contents' digests and compares those, not the
/// path as typed.
inline constexpr std::array<const char*, 2> kSiloFileOptions{"--material", "--geometry"};

/// `options` as `demcal silo` takes them (e.g. {"--material", "meal.json", "--theta", "30"}); `owner` names the
/// command in messages. Throws UserError naming the option and value; options that set a run's own outputs or
/// sessions (--out, --vtk, --export-bed, --checkpoint-every, --wall-limit, --resume, ...) are refused.
kernel::silo::SiloCaseSettings silo_case_settings(const std::vector<std::string>& options, const std::string& owner);

/// `options` (demcal silo's, as a campaign passes them on) in one spelling: each option given by its long name,
/// sorted, with its values; a number by its value (1e-3 and 0.001 are one), a --material or --geometry file by a
/// placeholder (its path, relative, absolute or through a link, says nothing of the run: its contents' digest is
/// compared apart, silo_input_file_digests). Two lists that run the same silo case compare equal; options that do
/// not parse are returned as given.
nlohmann::json canonical_silo_options(const std::vector<std::string>& options);

}  // namespace demcal
