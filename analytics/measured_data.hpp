// Measured data as CSV: a header of column names, SI units, angles in degrees, units in the names.
// Discharge data: geometry (conical|rectangular), D_m or b_m,c_m, outlet_m, theta_deg, d_p_m, rho_b_kg_m3, W_kg_s.
// Shear data: sigma_Pa, tau_Pa. Every other column is a covariate the models do not use (numeric when all its cells
// are numbers, else categorical, e.g. operator). Nothing is dropped: a missing or impossible value is an error naming
// the file, line and column.
#pragma once
#include <iosfwd>
#include <string>
#include <string_view>
#include <vector>

namespace demcal::analytics {

struct DataColumn {
    std::string name;
    bool numeric = true;
    std::vector<double> values;     // numeric columns: the numbers; NaN where a cell does not apply (D_m of a
                                    // rectangular row, b_m/c_m of a conical row)
    std::vector<std::string> text;  // every column: the cell text, trimmed
};

struct MeasuredData {
    std::string source;            // file name, used in messages
    std::vector<DataColumn> columns;
    std::vector<int> lines;        // file line (1 = header) of each row
    std::size_t rows() const { return lines.size(); }
    const DataColumn* find(std::string_view name) const;
    const DataColumn& at(std::string_view name) const;  // throws std::invalid_argument naming the column
    std::string where(std::size_t row, std::string_view column) const;  // "FILE: line L, column C"
};

enum class MeasuredKind { discharge, shear };

// The columns the loader checks for each kind (everything else is a covariate).
const std::vector<std::string>& reserved_columns(MeasuredKind kind);

// Parses CSV text (comma-separated, optional double quotes, '#' comment lines and blank lines skipped). Checks the
// shape (unique header names, the same number of fields on every line, no empty cells outside the geometry columns)
// and decides which columns are numeric; a cell that reads as a number must pass analytics::number_defect (no
// subnormal, non-finite or implausibly large values); throws std::invalid_argument naming line and column.
MeasuredData parse_csv(std::istream& in, const std::string& source);

// Checks the columns a kind needs and the physical sense of every value (positive sizes, outlet larger than the
// particles and smaller than the silo, 0 < theta <= 90, sigma >= 0 ...); throws std::invalid_argument naming the
// line, column and value.
void validate_measured(const MeasuredData& data, MeasuredKind kind);

// Measured data sets are a few hundred rows; a larger file is a wrong file.
inline constexpr std::size_t kMaxMeasuredDataBytes = std::size_t{64} << 20;

// A diagnosis costs about 2 ms per row and grows with every column (each is a candidate effect): the limits keep a
// wrong file from running for hours. Rows can be raised (diagnose --max-rows); columns cannot (no data set has 200).
inline constexpr std::size_t kMaxMeasuredRows = 10000;
inline constexpr std::size_t kMaxMeasuredColumns = 200;

// parse_csv + validate_measured on a file (read by analytics::read_input_file: a folder, a device or a file over
// kMaxMeasuredDataBytes is refused; so are more than max_rows rows, more than kMaxMeasuredColumns columns and lines
// ended by CR alone).
MeasuredData read_measured_csv(const std::string& path, MeasuredKind kind, std::size_t max_rows = kMaxMeasuredRows);

// The data back as CSV (numbers with 10 significant digits), e.g. to write generated sets.
std::string to_csv(const MeasuredData& data);

}  // namespace demcal::analytics
