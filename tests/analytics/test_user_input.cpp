// The one JSON reader and the data-file reader: every refusal names the input, the field and the rule, never crashes.
#include "analytics/measured_data.hpp"
#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>

using namespace demcal::analytics;
using Catch::Contains;
namespace fs = std::filesystem;

TEST_CASE("the JSON reader refuses deep nesting, duplicate keys and unusable numbers, naming the field", "[input]") {
    auto refused = [](const std::string& text, const std::string& expected) {
        CHECK_THROWS_AS(parse_json_text(text, "material = 'm.json'"), InputError);
        CHECK_THROWS_WITH(parse_json_text(text, "material = 'm.json'"), Contains(expected));
    };
    // 100,000 levels used to end in a segmentation fault when the value was printed in a message
    refused("{\"a\":" + std::string(100000, '[') + std::string(100000, ']') + "}", "nests deeper than 64 levels");
    refused(std::string(100000, '['), "nests deeper than 64 levels");
    refused(R"({"density": 1, "density": 2})", "material = 'm.json': field 'density' appears twice");
    refused(R"({"a": {"b": [1, {"c": 1, "c": 1}]}})", "field 'a.b[1].c' appears twice");
    refused(R"({"timestep_fraction": 1e-320})", "field 'timestep_fraction' = 1e-320 is subnormal");
    refused(R"({"rho": [1, 2, 1e308]})", "field 'rho[2]' = 1e+308 is implausibly large");
    refused(R"({"x": 1e400})", "is not valid JSON: field 'x': number overflow");  // the field named (probe 65)
    refused(R"({"a": {"b": [1, 0x10]}})", "is not valid JSON: in field 'a.b': ");
    refused(R"({"a": 1 "b": 2})", "is not valid JSON: after field 'a': ");
    // the position in the file, not the JSON library's own exception tag
    refused(R"({"x": tru})", "material = 'm.json' is not valid JSON: field 'x': parse error at line 1, column 10");
    CHECK_THROWS_WITH(parse_json_text(R"({"x": tru})", "m"), !Contains("json.exception"));
    // the parser took a NUL for the end: a valid object, a NUL and garbage was read as the object alone
    refused(std::string("{\"x\": 1}\0GARBAGE{{{", 20), "byte 9 is a NUL byte");
    refused("{\"x\": \"" + std::string(1000000, 'y'), "is not valid JSON");
    CHECK_THROWS_WITH(parse_json_text("{\"x\": \"" + std::string(1000000, 'y'), "m"),
                      Catch::Predicate<std::string>([](const std::string& m) { return m.size() < 400; },
                                                    "a message shorter than 400 characters"));
    // valid input still parses, with nesting up to the limit and the same key in different objects
    CHECK(parse_json_text(R"({"a": {"x": 1}, "b": {"x": 2.5e-3}, "c": [1e100, -1e-300, 0]})", "m")["b"]["x"] == 2.5e-3);
    CHECK(parse_json_text(std::string(64, '[') + std::string(64, ']'), "m").is_array());
}

TEST_CASE("a value in a message is shortened", "[input]") {
    const auto text = json_value_text(nlohmann::json(std::string(50'000'000, 'z')));
    CHECK(text.size() < 100);
    CHECK_THAT(text, Contains("50000002 characters"));
}

TEST_CASE("a value in a message has its control characters escaped: the message stays one line", "[input]") {
    CHECK(demcal::analytics::shortened_text("debug\ntouch x") == "debug\\ntouch x");
    CHECK(demcal::analytics::shortened_text("a\x1b[31mred\t\r") == "a\\x1b[31mred\\t\\r");
    CHECK(demcal::analytics::shortened_text("sand \xc3\xa9") == "sand \xc3\xa9");  // UTF-8 kept as it is
    const auto long_one = demcal::analytics::shortened_text(std::string(100, '\n'));
    CHECK(long_one.find('\n') == std::string::npos);
    CHECK_THAT(long_one, Contains("100 characters"));
}

TEST_CASE("input files: a folder, a missing file and an oversized file are refused by name", "[input]") {
    const fs::path dir = fs::temp_directory_path() / "demcal-test-user-input";
    fs::remove_all(dir);
    fs::create_directories(dir / "folder.json");
    CHECK_THROWS_WITH(read_json_input(dir / "folder.json", "material"), Contains("is a folder, not a file"));
    CHECK_THROWS_WITH(read_json_input(dir / "none.json", "material"), Contains("does not exist"));
    {
        std::ofstream big(dir / "big.json");
        big << "[" << std::string(kMaxJsonInputBytes, ' ') << "]";
    }
    CHECK_THROWS_WITH(read_json_input(dir / "big.json", "material"), Contains("more than the limit"));
    CHECK_THROWS_WITH(read_measured_csv((dir / "folder.json").string(), MeasuredKind::shear),
                      Contains("is a folder, not a file"));
    std::ofstream(dir / "ok.json") << R"({"a": 1})";
    CHECK(read_json_input(dir / "ok.json", "material")["a"] == 1);
    fs::remove_all(dir);
}

TEST_CASE("measured data: subnormal, non-finite and implausible numbers are named as such", "[input][measured]") {
    auto refused = [](const std::string& cell, const std::string& expected) {
        std::istringstream in("sigma_Pa,tau_Pa\n1000,800\n2000," + cell + "\n");
        CHECK_THROWS_WITH(parse_csv(in, "shear.csv"), Contains("line 3, column tau_Pa: " + expected));
    };
    refused("1e-320", "'1e-320' is subnormal");
    refused("inf", "'inf' is not finite");
    refused("nan", "'nan' is not a number");
    refused("1e400", "'1e400' is too large for a double");
    refused("1e300", "'1e300' is implausibly large");
    std::istringstream long_cell("sigma_Pa,tau_Pa\n1000,800\n2000,1x" + std::string(100000, '9') + "\n");
    CHECK_THROWS_WITH(parse_csv(long_cell, "shear.csv"), Contains("(100002 characters)"));
}
