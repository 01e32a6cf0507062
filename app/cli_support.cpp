#include "app/cli_support.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"
#include "app/commands.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>
#include <functional>

namespace demcal {

nlohmann::json read_json_file(const std::string& path, const std::string& field) {
    try {
        return analytics::read_json_input(path, field);
    } catch (const analytics::InputError& e) {
        throw UserError(e.what());
    }
}

namespace {

// A validator that accepts a finite number for which `ok` holds; `what` completes "VALUE is not ...".
CLI::Validator number_check(const std::string& what, std::function<bool(double)> ok) {
    return CLI::Validator(
        [what, ok](std::string& text) -> std::string {
            double v = 0;
            size_t used = 0;
            try {
                v = std::stod(text, &used);
            } catch (const std::exception&) {
                used = 0;
            }
            if (used == 0 || used != text.size()) return "'" + text + "' is not a number";
            if (!std::isfinite(v) || !ok(v)) return text + " is not " + what;
            return {};
        },
        what);
}

}  // namespace

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
