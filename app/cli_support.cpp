#include "app/cli_support.hpp"

#include "app/commands.hpp"

#include <cmath>
#include <cstdio>
#include <fstream>

namespace demcal {

nlohmann::json read_json_file(const std::string& path, const std::string& field) {
    std::ifstream f(path);
    if (!f) throw UserError(field + " = '" + path + "' cannot be read");
    try {
        return nlohmann::json::parse(f);
    } catch (const nlohmann::json::parse_error& e) {
        throw UserError(field + " = '" + path + "' is not valid JSON: " + e.what());
    }
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
