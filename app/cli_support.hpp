// Small helpers every subcommand shares: reading a JSON input file, printing a duration.
#pragma once
#include <nlohmann/json.hpp>

#include <string>

namespace demcal {

// Parses the JSON file at `path`; a missing file or bad JSON is a UserError naming `field` and the path.
nlohmann::json read_json_file(const std::string& path, const std::string& field);

// "42s", "3m05s", "2h10m": short enough for a progress line; "?" for a negative (unknown) duration.
std::string duration_text(double seconds);

}  // namespace demcal
