// Bad silo settings: one message shape for every check, "field = value: why", thrown as SettingRejected (a
// std::invalid_argument that keeps the field's name, so that a front end can name it as its user gave it).
#pragma once
#include <sstream>
#include <stdexcept>
#include <string>
#include <utility>

namespace demcal::kernel::silo {

// A value as the user would type it (shortest default stream form).
inline std::string setting_text(double value) {
    std::ostringstream s;
    s << value;
    return s.str();
}

struct SettingRejected : std::invalid_argument {
    SettingRejected(std::string field_name, std::string value_and_why)
        : std::invalid_argument(field_name + value_and_why),
          field(std::move(field_name)),
          after_field(std::move(value_and_why)) {}
    // a rule on two settings together: "field = value with other = value: why"
    SettingRejected(std::string field_name, double value, std::string other_name, double other_value,
                    const std::string& why)
        : SettingRejected(std::move(field_name), " = " + setting_text(value) + " with " + other_name + " = " +
                                                     setting_text(other_value) + ": " + why) {
        other_field = std::move(other_name);
    }
    std::string field;        // as the message's start names it
    std::string after_field;  // the rest: " = value: why" (or " = value with other_field = value: why")
    std::string other_field;  // the second setting of a rule on two, named in after_field; "" for one

    /// The message with each setting named by `name(field)` (a front end's own name for it, e.g. its option).
    template <class Name>
    std::string message(const Name& name) const {
        std::string rest = after_field;
        if (!other_field.empty())
            if (const auto at = rest.find(" with " + other_field + " = "); at != std::string::npos)
                rest.replace(at + 6, other_field.size(), name(other_field));
        return name(field) + rest;
    }
};

[[noreturn]] inline void reject_setting(const std::string& field, double value, const std::string& why) {
    throw SettingRejected(field, " = " + setting_text(value) + ": " + why);
}

}  // namespace demcal::kernel::silo
