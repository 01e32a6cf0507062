// How a value given by a user shows in a message, and the rule every number read from a user follows (JSON inputs,
// CSV data, command-line options): one place, so every reader refuses the same numbers with the same words.
#pragma once
#include <cmath>
#include <optional>
#include <sstream>
#include <string>
#include <string_view>

namespace demcal::analytics {

// A number as a message shows it: the shortest stream form ("0.035", "1e+10"), so an error names a value as typed.
inline std::string number_text(double value, int significant_digits = 6) {
    std::ostringstream s;
    s.precision(significant_digits);
    s << value;
    return s.str();
}

// A value as a message shows it: whole when short, else its start and how long it was (a 50 MB string in an input
// must not end up on stderr in full).
inline std::string shortened_text(std::string_view text, std::size_t max_chars = 60) {
    if (text.size() <= max_chars) return std::string(text);
    return std::string(text.substr(0, max_chars)) + "... (" + std::to_string(text.size()) + " characters)";
}

// Beyond this magnitude no input of demcal is a measurement or a setting, only a typo (1e308 for 1e3).
inline constexpr double kLargestPlausibleNumber = 1e100;

// Why a number read from a user cannot be used, or nothing when it can. Subnormals are refused because arithmetic on
// them loses precision and can stall a time loop (a step of 1e-320 s never advances the clock).
inline std::optional<std::string> number_defect(double value) {
    if (std::isnan(value)) return "is not a number";
    if (std::isinf(value)) return "is not finite";
    if (std::fpclassify(value) == FP_SUBNORMAL) return "is subnormal (too close to 0 to compute with)";
    if (std::fabs(value) > kLargestPlausibleNumber)
        return "is implausibly large (|value| > " + number_text(kLargestPlausibleNumber) + ")";
    return std::nullopt;
}

}  // namespace demcal::analytics
