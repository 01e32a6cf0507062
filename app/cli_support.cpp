#include "app/cli_support.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"
#include "app/commands.hpp"

#include <cctype>
#include <cerrno>
#include <charconv>
#include <cmath>
#include <cstdlib>
#include <cstdio>
#include <fstream>
#include <filesystem>
#include <functional>

#include <unistd.h>

namespace demcal {

nlohmann::json read_json_file(const std::string& path, const std::string& field) {
    try {
        return analytics::read_json_input(path, field);
    } catch (const analytics::InputError& e) {
        throw UserError(e.what());
    }
}

namespace {

constexpr const char* kEmptyValue = "an empty value (omit the option to get its default)";

// A validator that accepts a number for which `ok` holds; `what` completes "VALUE is not ...". The text is read by
// strtod, so a subnormal or an overflowing exponent is named as such by analytics::number_defect, not as "not a
// number".
CLI::Validator number_check(const std::string& what, std::function<bool(double)> ok) {
    return CLI::Validator(
        [what, ok](std::string& text) -> std::string {
            if (text.empty()) return kEmptyValue;
            const std::string shown = "'" + analytics::shortened_text(text) + "'";
            const auto n = analytics::read_typed_number(text);
            if (!n.is_number) return shown + " is not a number";
            if (n.defect) return shown + " " + *n.defect;
            const double v = n.value;
            if (!ok(v)) return text + " is not " + what;
            return {};
        },
        what);
}

}  // namespace

CLI::Validator integer_in(long long lo, long long hi) {
    const std::string what = "an integer between " + std::to_string(lo) + " and " + std::to_string(hi);
    return CLI::Validator(
        [what, lo, hi](std::string& text) -> std::string {
            if (text.empty()) return kEmptyValue;
            long long v = 0;
            const char* begin = text.c_str() + (text.front() == '+' ? 1 : 0);
            const auto [end, ec] = std::from_chars(begin, text.c_str() + text.size(), v);
            const std::string shown = "'" + analytics::shortened_text(text) + "'";
            if (end != text.c_str() + text.size() || (ec != std::errc() && ec != std::errc::result_out_of_range))
                return shown + " is not an integer";
            // out of range of a long long (a seed above 2^63 was silently clamped to 2^63 - 1)
            if (ec == std::errc::result_out_of_range || v < lo || v > hi) return shown + " is not " + what;
            return {};
        },
        what);
}

void refuse_empty_values(CLI::App& app) {
    for (CLI::Option* opt : app.get_options())
        if (opt->get_type_size_max() > 0)  // takes values (a flag takes none)
            opt->check(CLI::Validator([](std::string& text) { return text.empty() ? kEmptyValue : std::string(); },
                                      ""));
    for (CLI::App* sub : app.get_subcommands([](CLI::App*) { return true; })) refuse_empty_values(*sub);
}

CLI::Validator number_in(double lo, double hi) {
    return number_check("between " + analytics::number_text(lo) + " and " + analytics::number_text(hi),
                        [lo, hi](double v) { return v >= lo && v <= hi; });
}

CLI::Validator positive_number() {
    return number_check("a positive number", [](double v) { return v > 0; });
}

CLI::Validator non_negative_number() {
    return number_check("a number >= 0", [](double v) { return v >= 0; });
}

void check_output_file(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    const std::string named = option + " = '" + analytics::shortened_text(path, 200) + "'";
    if (path.empty()) throw UserError(option + ": an empty path");
    std::error_code ec;
    if (fs::is_directory(path, ec)) throw UserError(named + " is a folder; give a file name");
    const fs::path folder = fs::path(path).parent_path().empty() ? fs::path(".") : fs::path(path).parent_path();
    if (!fs::is_directory(folder, ec)) throw UserError(named + ": the folder " + folder.string() + " does not exist");
    if (::access(folder.c_str(), W_OK | X_OK) != 0)
        throw UserError(named + ": the folder " + folder.string() + " is not writable");
    if (fs::exists(path, ec) && ::access(path.c_str(), W_OK) != 0) throw UserError(named + " is not writable");
}

void check_output_file_in_new_folders(const std::string& path, const std::string& option) {
    namespace fs = std::filesystem;
    if (path.empty()) return;
    std::error_code ec;
    const fs::path parent = fs::path(path).parent_path();
    if (parent.empty() || fs::exists(parent, ec)) return check_output_file(path, option);
    fs::path existing = parent;
    while (!existing.empty() && !fs::exists(existing, ec)) existing = existing.parent_path();
    if (existing.empty()) existing = ".";
    const std::string named = option + " = '" + analytics::shortened_text(path, 200) + "'";
    if (!fs::is_directory(existing, ec)) throw UserError(named + ": " + existing.string() + " is not a folder");
    if (::access(existing.c_str(), W_OK | X_OK) != 0)
        throw UserError(named + ": the folder " + existing.string() + " is not writable");
}

std::string duration_text(double seconds) {
    if (!(seconds >= 0)) return "?";
    char buf[32];
    const long t = std::lround(seconds);
    if (t >= 3600)
        std::snprintf(buf, sizeof buf, "%ldh%02ldm", t / 3600, (t / 60) % 60);
    else if (t >= 60)
        std::snprintf(buf, sizeof buf, "%ldm%02lds", t / 60, t % 60);
    else
        std::snprintf(buf, sizeof buf, "%lds", t);
    return buf;
}

}  // namespace demcal
