#include "analytics/measured_data.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <sstream>

using namespace demcal::analytics;

namespace {
MeasuredData load(const std::string& csv, MeasuredKind kind = MeasuredKind::discharge) {
    std::istringstream in(csv);
    auto data = parse_csv(in, "set.csv");
    validate_measured(data, kind);
    return data;
}
const std::string header = "geometry,D_m,b_m,c_m,outlet_m,theta_deg,d_p_m,rho_b_kg_m3,W_kg_s,operator,moisture_pct\n";
}  // namespace

TEST_CASE("discharge CSV loads every row with covariates", "[measured]") {
    const auto data = load(header +
                           "# a comment line\n"
                           "conical,0.105,,,0.035,30,0.0055,780,0.171,anna,12.5\n"
                           "\n"
                           "rectangular,,0.05,0.1,0.03,60,0.0055,780,0.35,\"bob, jr\",13\n");
    REQUIRE(data.rows() == 2);
    CHECK(data.lines == std::vector<int>{3, 5});
    CHECK(data.at("W_kg_s").values[1] == Approx(0.35));
    CHECK(std::isnan(data.at("D_m").values[1]));
    CHECK_FALSE(data.at("operator").numeric);
    CHECK(data.at("operator").text[1] == "bob, jr");
    CHECK(data.at("moisture_pct").numeric);
    // Written back and read again it is the same table.
    std::istringstream again(to_csv(data));
    const auto round = parse_csv(again, "again.csv");
    CHECK(round.at("operator").text[1] == "bob, jr");
    CHECK(round.at("W_kg_s").values[0] == Approx(0.171));
}

TEST_CASE("a quoted field may hold line breaks (RFC 4180), and a quote never closed is named at its line", "[measured]") {
    // a spreadsheet's notes cell of two lines: it was refused as an unterminated quote
    const auto data = load(header + "conical,0.105,,,0.035,30,0.0055,780,0.171,\"anna\nwith bob, after rain\",12.5\n" +
                           "conical,0.105,,,0.035,45,0.0055,780,0.15,\"\"\"quoted\"\"\",13\n");
    REQUIRE(data.rows() == 2);
    CHECK(data.lines == std::vector<int>{2, 4});  // the line each row starts on
    CHECK(data.at("operator").text[0] == "anna\nwith bob, after rain");
    CHECK(data.at("operator").text[1] == "\"quoted\"");
    CHECK(data.at("moisture_pct").values[0] == Approx(12.5));
    std::istringstream again(to_csv(data));  // written back quoted, read back the same
    CHECK(parse_csv(again, "again.csv").at("operator").text[0] == "anna\nwith bob, after rain");
    // a row after a field with a line break keeps its own line number in messages
    CHECK_THROWS_WITH(load(header + "conical,0.105,,,0.035,30,0.0055,780,0.171,\"a\nb\",12.5\n" +
                           "conical,0.105,,,0.035,30,0.0055,780,-1,anna,12.5\n"),
                      Catch::Contains("line 4, column W_kg_s"));
    // never closed: named at the line it opens, after one pass over the rest (100,000 lines, not a pass per line)
    std::string open = header + "conical,0.105,,,0.035,30,0.0055,780,0.171,\"anna,12.5\n";
    for (int i = 0; i < 100000; ++i) open += "conical,0.105,,,0.035,30,0.0055,780,0.171,anna,12.5\n";
    CHECK_THROWS_WITH(load(open), Catch::Contains("set.csv: line 2: unterminated quote"));
}

TEST_CASE("a spreadsheet's UTF-8 byte-order mark and CRLF line ends are read, UTF-16 is refused", "[measured]") {
    const std::string row = "conical,0.105,,,0.035,30,0.0055,780,0.171,anna,12.5\n";
    const auto with_mark = load("\xEF\xBB\xBF" + header + row);
    CHECK(with_mark.find("geometry") != nullptr);
    CHECK(with_mark.at("W_kg_s").values[0] == Approx(0.171));
    // the mark before a comment line: the comment is still a comment
    const auto comment_first = load("\xEF\xBB\xBF# exported\n" + header + row);
    CHECK(comment_first.rows() == 1);
    std::string crlf;
    for (const char c : header + row) crlf += c == '\n' ? std::string("\r\n") : std::string(1, c);
    CHECK(load(crlf).at("moisture_pct").values[0] == Approx(12.5));
    CHECK_THROWS_WITH(load(std::string("\xFF\xFEg\0e\0o\0", 8) + "\n"), Catch::Contains("UTF-16"));
}

TEST_CASE("a CRLF file with every field quoted reads its last column as the others, without the line end",
          "[measured]") {
    // Python's csv.QUOTE_ALL and spreadsheets' "quote all" exports: "moisture_pct"\r\n; the last column was
    // "moisture_pct\r", another and categorical column (probe 61)
    const auto quoted_all = [](const std::string& after_quote, const std::string& line_end) {
        std::string text;
        for (const std::string& line : {header, std::string("conical,0.105,,,0.035,30,0.0055,780,0.171,anna,12.5\n")}) {
            std::string fields = "\"";
            for (const char c : line.substr(0, line.size() - 1))
                fields += c == ',' ? "\"" + after_quote + ",\"" : std::string(1, c);
            text += fields + "\"" + after_quote + line_end;
        }
        return text;
    };
    for (const auto& [after_quote, line_end] : {std::pair{std::string(""), std::string("\r\n")},
                                                std::pair{std::string("  "), std::string("\n")},
                                                std::pair{std::string(" \t"), std::string("\r\n")}}) {
        const auto data = load(quoted_all(after_quote, line_end));
        REQUIRE(data.find("moisture_pct") != nullptr);
        CHECK(data.at("moisture_pct").values[0] == Approx(12.5));
        CHECK(data.at("W_kg_s").values[0] == Approx(0.171));
    }
}

TEST_CASE("a file separated by semicolons or tabs is named as such, not by its rows' field counts", "[measured]") {
    // a spreadsheet set to decimal commas saves "CSV" as geometry;D_m;...: every row then had "7 fields, the header
    // has 1"
    CHECK_THROWS_WITH(load("geometry;D_m;outlet_m\nconical;0,105;0,035\n"),
                      Catch::Contains("line 1: the header 'geometry;D_m;outlet_m' is one column") &&
                          Catch::Contains("this file separates them by ';'"));
    CHECK_THROWS_WITH(load("geometry\tD_m\toutlet_m\nconical\t0.105\t0.035\n"),
                      Catch::Contains("the header 'geometry\\tD_m\\toutlet_m' is one column") &&
                          Catch::Contains("separates them by tabs"));
    // a material or geometry given where the table belongs
    CHECK_THROWS_WITH(load("{\n  \"density\": 2650,\n  \"young_modulus\": 1e8\n}\n"),
                      Catch::Contains("line 1 starts with '{': a JSON file, not a table"));
}

TEST_CASE("bad discharge files name the line and the column", "[measured]") {
    const std::string good = "conical,0.105,,,0.035,30,0.0055,780,0.171,anna,12.5\n";
    auto fails_with = [&](const std::string& body, const std::string& expected) {
        CHECK_THROWS_WITH(load(header + good + body), Catch::Contains(expected));
    };
    fails_with("conical,0.105,,,abc,30,0.0055,780,0.171,anna,12.5\n", "line 3, column outlet_m: 'abc' is not a number");
    fails_with("conical,0.105,,,0.035,30,-0.0055,780,0.171,anna,12.5\n", "line 3, column d_p_m: -0.0055");
    fails_with("conical,0.105,,,0.004,30,0.0055,780,0.171,anna,12.5\n",
               "line 3, column outlet_m: 0.004 is not larger than the particles");
    fails_with("conical,0.105,,,0.2,30,0.0055,780,0.171,anna,12.5\n", "line 3, column outlet_m: 0.2 is not smaller");
    fails_with("conical,0.105,,,0.035,95,0.0055,780,0.171,anna,12.5\n", "line 3, column theta_deg: 95");
    fails_with("conical,0.105,,,0.035,30,0.0055,780,,anna,12.5\n", "line 3, column W_kg_s: missing value");
    // finite but absurd values were diagnosed as data: the same bounds as a geometry file's (predict)
    fails_with("conical,0.105,,,0.035,30,0.0055,1e90,0.171,anna,12.5\n",
               "line 3, column rho_b_kg_m3: 1e+90 outside [10, 20000] kg/m^3");
    fails_with("conical,0.105,,,0.035,30,0.0055,780,5e7,anna,12.5\n", "line 3, column W_kg_s: 50000000 outside");
    fails_with("conical,1e4,,,0.035,30,0.0055,780,0.171,anna,12.5\n", "line 3, column D_m: 10000 outside [0, 100] m");
    fails_with("conical,0.105,,,0.035,30,1e-9,780,0.171,anna,12.5\n", "line 3, column d_p_m: 1e-09 outside");
    fails_with("conical,,,,0.035,30,0.0055,780,0.171,anna,12.5\n", "line 3, column D_m: missing value");
    fails_with("conical,0.105,,,0.035,30,0.0055,780,0.171,,12.5\n", "line 3, column operator: missing value");
    fails_with("conical,0.105,,,0.035,30,0.0055,780,0.171,anna,1 2\n", "line 3, column moisture_pct: '1 2'");
    fails_with("hexagonal,0.105,,,0.035,30,0.0055,780,0.171,anna,12.5\n", "line 3, column geometry: 'hexagonal'");
    // a size of the other shape was read by no model, silently (probe 59b: b_m and c_m on conical rows)
    fails_with("conical,0.105,0.05,,0.035,30,0.0055,780,0.171,anna,12.5\n",
               "line 3, column b_m: '0.05' on a conical silo's row, where no model reads it");
    fails_with("rectangular,0.105,0.05,0.1,0.03,60,0.0055,780,0.35,anna,12.5\n",
               "line 3, column D_m: '0.105' on a rectangular silo's row");
    fails_with("conical,0.105,,,0.035,30,0.0055,780\n", "line 3: 8 fields, the header has 11");
    fails_with("conical,0,105,,,0.035,30,0.0055,780,0.171,anna,12.5\n",
               "line 3: 12 fields, the header has 11 (a decimal comma, 0,105,");
    CHECK_THROWS_WITH(load("geometry,outlet_m,theta_deg,d_p_m,W_kg_s\nconical,0.035,30,0.0055,0.17\n"),
                      Catch::Contains("missing column rho_b_kg_m3"));
    CHECK_THROWS_WITH(load("sigma_Pa,tau_Pa\n1000,800\n2000,-5\n", MeasuredKind::shear),
                      Catch::Contains("line 3, column tau_Pa: -5"));
    CHECK_THROWS_WITH(load("sigma_Pa,sigma_Pa\n1,2\n", MeasuredKind::shear), Catch::Contains("duplicate column"));
    CHECK_THROWS_WITH(load("sigma_Pa,tau_Pa\n1000,800\n2e12,5\n", MeasuredKind::shear),
                      Catch::Contains("line 3, column sigma_Pa: 2e+12 Pa is above 1e+09 Pa"));
}
