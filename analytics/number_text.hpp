// A number as a message shows it: the shortest stream form ("0.035", "1e+10"), so an error names a value as typed.
#pragma once
#include <sstream>
#include <string>

namespace demcal::analytics {

inline std::string number_text(double value, int significant_digits = 6) {
    std::ostringstream s;
    s.precision(significant_digits);
    s << value;
    return s.str();
}

}  // namespace demcal::analytics
