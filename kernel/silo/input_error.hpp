// Bad silo settings: one message shape for every check, "field = value: why", thrown as SettingRejected (a
// std::invalid_argument that keeps the field's name, so that a front end can name it as its user gave it).
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace demcal::kernel::silo {

struct SettingRejected : std::invalid_argument {
    SettingRejected(std::string field_name, std::string value_and_why)
        : std::invalid_argument(field_name + value_and_why),
          field(std::move(field_name)),
          after_field(std::move(value_and_why)) {}
    std::string field;        // as the message's start names it
    std::string after_field;  // the rest: " = value: why"
};

// A value as the user would type it (shortest default stream form).
inline std::string setting_text(double value) {
    std::ostringstream s;
    s << value;
    return s.str();
}

[[noreturn]] inline void reject_setting(const std::string& field, double value, const std::string& why) {
    throw SettingRejected(field, " = " + setting_text(value) + ": " + why);
}

}  // namespace demcal::kernel::silo
