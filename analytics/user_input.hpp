// The one place where files a user gives are read: JSON inputs (materials, geometries, sensitivity studies, the
// store's and the runs' JSON) and the text of data files. Every reader refuses the same things the same way: a folder
// or a device where a file is expected, a file beyond its size limit, JSON nested deeper than a limit (a 100,000-deep
// array used to crash), duplicate keys (the last silently won), and numbers that are subnormal, not finite or
// implausibly large (analytics::number_defect); the message names the input, the field and the rule, the value shown
// shortened.
#pragma once
#include <nlohmann/json.hpp>

#include <cstddef>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <string_view>

namespace demcal::analytics {

// Bad input from a file: an invalid_argument, so every command ends it with exit code 2.
struct InputError : std::invalid_argument {
    using std::invalid_argument::invalid_argument;
};

inline constexpr std::size_t kMaxJsonInputBytes = std::size_t{16} << 20;  // a material is 1 kB, a study 100 kB
inline constexpr int kMaxJsonDepth = 64;                                  // demcal's own files nest 4 deep

// The whole content of the regular file `file`, at most `max_bytes`; `what` names the input in messages
// ("material = 'sand.json'"). Throws InputError for a missing, unreadable, non-regular or too large file.
std::string read_input_file(const std::filesystem::path& file, const std::string& what, std::size_t max_bytes);

// Parses JSON text under the rules above; `what` names the input in messages. Throws InputError.
nlohmann::json parse_json_text(std::string_view text, const std::string& what);

// read_input_file + parse_json_text; the input is named `field = 'file'` in messages.
nlohmann::json read_json_input(const std::filesystem::path& file, const std::string& field);

// A JSON value as a message shows it: dumped, shortened (analytics::shortened_text).
std::string json_value_text(const nlohmann::json& value);

}  // namespace demcal::analytics
