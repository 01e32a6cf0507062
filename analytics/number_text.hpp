// How a value given by a user shows in a message, and the rule every number read from a user follows (JSON inputs,
// CSV data, command-line options): one place, so every reader refuses the same numbers with the same words.
#pragma once
#include <cctype>
#include <cerrno>
#include <cmath>
#include <cstdlib>
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

// `s` without the blanks (what isspace calls blank: spaces, tabs, line ends, \v, \f) at its two ends: a CSV cell, a
// list item typed "5e3, 1e4", a value pasted with its line end.
inline std::string trimmed(std::string_view s) {
    constexpr const char* blanks = " \t\r\n\v\f";
    const auto first = s.find_first_not_of(blanks);
    if (first == std::string_view::npos) return {};
    return std::string(s.substr(first, s.find_last_not_of(blanks) - first + 1));
}

// Whether a comma-separated list has an empty item: two commas in a row, one at an end, or an item of blanks only
// ("5e3, ,1e4"); the whole text empty or blank is one empty item.
inline bool has_empty_list_item(std::string_view list) {
    for (std::size_t start = 0;;) {
        const std::size_t end = list.find(',', start);
        if (trimmed(list.substr(start, end == std::string_view::npos ? end : end - start)).empty()) return true;
        if (end == std::string_view::npos) return false;
        start = end + 1;
    }
}

// A value as a message shows it: whole when short, else its start and how long it was (a 50 MB string in an input
// must not end up on stderr in full); control characters escaped (\n, \x1b), so that a message stays one line and a
// value cannot move the terminal's cursor or colour.
inline std::string shortened_text(std::string_view text, std::size_t max_chars = 60) {
    std::string shown;
    for (char c : text.substr(0, max_chars)) {
        const auto u = static_cast<unsigned char>(c);
        if (c == '\n') shown += "\\n";
        else if (c == '\t') shown += "\\t";
        else if (c == '\r') shown += "\\r";
        else if (u < 0x20 || u == 0x7f) {
            static const char hex[] = "0123456789abcdef";
            shown += "\\x";
            shown += hex[u >> 4];
            shown += hex[u & 15];
        } else shown += c;
    }
    if (text.size() <= max_chars) return shown;
    return shown + "... (" + std::to_string(text.size()) + " characters)";
}

// A control character (a newline, a tab, an escape) in a path: no batch script line, plot command or log line can
// carry it, so an output path holding one is refused (analytics::shortened_text shows it escaped).
inline bool has_control_character(std::string_view text) {
    for (char c : text)
        if (static_cast<unsigned char>(c) < 0x20 || c == 0x7f) return true;
    return false;
}

// Whether `text` is UTF-8 (no stray, truncated or overlong sequence, no surrogate, nothing above U+10FFFF): a text of
// an input that is not cannot be written into a JSON result, and would be copied into a report as raw bytes.
inline bool is_utf8(std::string_view text) {
    std::size_t i = 0;
    while (i < text.size()) {
        const auto b = static_cast<unsigned char>(text[i]);
        if (b < 0x80) {
            ++i;
            continue;
        }
        int more = 0;
        unsigned lowest = 0, code = 0;
        if ((b & 0xe0) == 0xc0) more = 1, lowest = 0x80, code = b & 0x1f;
        else if ((b & 0xf0) == 0xe0) more = 2, lowest = 0x800, code = b & 0x0f;
        else if ((b & 0xf8) == 0xf0) more = 3, lowest = 0x10000, code = b & 0x07;
        else return false;
        if (i + std::size_t(more) >= text.size()) return false;  // cut short at the end
        for (int k = 1; k <= more; ++k) {
            const auto c = static_cast<unsigned char>(text[i + k]);
            if ((c & 0xc0) != 0x80) return false;
            code = (code << 6) | (c & 0x3f);
        }
        if (code < lowest || code > 0x10ffff || (code >= 0xd800 && code <= 0xdfff)) return false;
        i += std::size_t(more) + 1;
    }
    return true;
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

// A number typed by a user (an option, a CSV cell, a target), read whole by strtod: `is_number` is false when the
// text is no number at all; otherwise `value`, and `defect` says why it cannot be used (number_defect, or an exponent
// beyond a double's range).
struct TypedNumber {
    bool is_number = false;
    double value = 0;
    std::optional<std::string> defect;
};

inline TypedNumber read_typed_number(const std::string& text) {
    TypedNumber n;
    if (text.empty() || std::isspace(static_cast<unsigned char>(text.front()))) return n;
    // strtod reads hexadecimal (0x10, 0x1p9) too; JSON and the integer options do not: one rule, decimal only
    if (text.find_first_of("xX") != std::string::npos) return n;
    char* end = nullptr;
    errno = 0;
    n.value = std::strtod(text.c_str(), &end);
    n.is_number = end == text.c_str() + text.size();
    if (!n.is_number) return n;
    if (errno == ERANGE && std::isinf(n.value)) n.defect = "is too large for a double";
    else if (errno == ERANGE && n.value == 0) n.defect = "is too close to 0 for a double (it would read as 0)";
    else n.defect = number_defect(n.value);
    return n;
}

}  // namespace demcal::analytics
