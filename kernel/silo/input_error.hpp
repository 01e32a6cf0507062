// Bad silo settings: one message shape for every check, "field = value: why", thrown as std::invalid_argument.
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>

namespace demcal::kernel::silo {

// A value as the user would type it (shortest default stream form).
inline std::string setting_text(double value) {
    std::ostringstream s;
    s << value;
    return s.str();
}

[[noreturn]] inline void reject_setting(const std::string& field, double value, const std::string& why) {
    throw std::invalid_argument(field + " = " + setting_text(value) + ": " + why);
}

}  // namespace demcal::kernel::silo
