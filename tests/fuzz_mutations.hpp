// Seeded mutations of a valid input for the readers' fuzz tests: byte flips, truncations, insertions of bytes and of
// JSON/CSV structure, deep nesting and repeated slices. Deterministic for a seed, so a failure can be replayed.
#pragma once
#include <cstdint>
#include <random>
#include <string>

namespace demcal::test {

inline std::string mutated(const std::string& valid, std::uint32_t seed) {
    std::mt19937 rng(seed);
    auto pick = [&](std::size_t n) { return n == 0 ? std::size_t{0} : std::uniform_int_distribution<std::size_t>(0, n - 1)(rng); };
    static const char* const pieces[] = {"{", "}", "[", "]", ",", ":", "\"", "\\", "\n", "\r\n", "#", "1e-320", "1e400",
                                         "-0", "nan", "inf", "1e308", "9223372036854775808", "\"x\":", "\xff\xfe", "\0"};
    std::string s = valid;
    const int edits = 1 + static_cast<int>(pick(4));
    for (int e = 0; e < edits; ++e) {
        const std::size_t at = pick(s.size() + 1);
        switch (pick(6)) {
            case 0:  // flip one bit
                if (!s.empty()) s[pick(s.size())] ^= static_cast<char>(1u << pick(8));
                break;
            case 1:  // truncate
                s.resize(at);
                break;
            case 2:  // insert a random byte
                s.insert(at, 1, static_cast<char>(pick(256)));
                break;
            case 3: {  // insert a piece of structure or a troublesome number
                const std::string piece = pieces[pick(sizeof pieces / sizeof *pieces)];
                s.insert(at, piece.empty() ? std::string(1, '\0') : piece);
                break;
            }
            case 4: {  // nest deeply
                const std::size_t depth = 1 + pick(5000);
                s.insert(at, std::string(depth, pick(2) ? '[' : '{'));
                break;
            }
            default: {  // repeat a slice (duplicate keys, rows, columns)
                const std::size_t from = pick(s.size() + 1), len = pick(200);
                s.insert(at, s.substr(from, len));
                break;
            }
        }
    }
    return s;
}

}  // namespace demcal::test
