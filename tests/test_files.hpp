// Reading back what a run under test wrote (logs, CSV, JSON): one helper for every test module.
#pragma once
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

namespace demcal::test {

// The whole file, byte for byte; empty when it cannot be opened (the test then fails on what it expected to find).
inline std::string read_file(const std::filesystem::path& file) {
    std::ifstream f(file, std::ios::binary);
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

}  // namespace demcal::test
