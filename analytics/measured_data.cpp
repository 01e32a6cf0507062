#include "analytics/measured_data.hpp"

#include "analytics/discharge_models.hpp"
#include "analytics/failure_line.hpp"

#include "analytics/number_text.hpp"
#include "analytics/user_input.hpp"

#include <algorithm>
#include <charconv>
#include <cmath>
#include <istream>
#include <limits>
#include <optional>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace demcal::analytics {

namespace {

constexpr double nan = std::numeric_limits<double>::quiet_NaN();

// Strict: the whole cell is one finite number (no "12 kg", no "1,5", no "nan"/"inf").
std::optional<double> parse_number(const std::string& cell) {
    if (cell.empty()) return std::nullopt;
    const char* begin = cell.data();
    if (*begin == '+') ++begin;
    double v = 0;
    const auto [end, ec] = std::from_chars(begin, cell.data() + cell.size(), v);
    if (ec != std::errc() || end != cell.data() + cell.size() || !std::isfinite(v)) return std::nullopt;
    return v;
}

// Splits one record into fields, a piece at a time: RFC 4180 lets a quoted field hold line breaks (a spreadsheet's
// notes cell of two lines), so a record left inside a quote goes on with the next line. Linear in the text: a file
// that opens a quote and never closes it costs one pass, not one pass per line.
class CsvRecordSplitter {
public:
    void feed(std::string_view text) {
        for (std::size_t i = 0; i < text.size(); ++i) {
            const char ch = text[i];
            if (quoted_) {
                if (ch == '"' && i + 1 < text.size() && text[i + 1] == '"') {
                    append('"');
                    ++i;
                } else if (ch == '"') {
                    quoted_ = false;
                    quoted_end_ = cur_.size();
                } else {
                    append(ch);
                }
            } else if (ch == '"' && cur_blank_) {
                quoted_ = was_quoted_ = true;
                cur_.clear();
            } else if (ch == ',') {
                end_field();
            } else {
                append(ch);
            }
        }
    }
    bool open_quote() const { return quoted_; }
    std::vector<std::string> finish() {
        end_field();
        return std::move(fields_);
    }

private:
    void append(char ch) {
        cur_ += ch;
        cur_blank_ = cur_blank_ && (ch == ' ' || ch == '\t' || ch == '\r');
    }
    void end_field() {
        // blanks after a closing quote are not the field's: a CRLF file's "last field"\r kept its \r (probe 61: the
        // column "vibration_Hz\r" became another, categorical one; a quoted response column was "missing")
        if (was_quoted_ && trimmed(std::string_view(cur_).substr(quoted_end_)).empty()) cur_.resize(quoted_end_);
        fields_.push_back(was_quoted_ ? cur_ : trimmed(cur_));
        cur_.clear();
        cur_blank_ = true;
        was_quoted_ = false;
    }
    std::vector<std::string> fields_;
    std::string cur_;
    std::size_t quoted_end_ = 0;  // where the closing quote left cur_
    bool cur_blank_ = true, quoted_ = false, was_quoted_ = false;
};

// Cells that may be empty: the geometry-specific sizes (they apply to one geometry only).
bool may_be_empty(const std::string& column) { return column == "D_m" || column == "b_m" || column == "c_m"; }

std::string quote(const std::string& s) {
    std::string quoted = "'";  // appended, not "'" + ... + "'": GCC 12 warns falsely (-Wrestrict) on the latter
    quoted += shortened_text(s);
    quoted += '\'';
    return quoted;
}

std::string num(double v) {
    std::ostringstream s;
    s.precision(10);
    s << v;
    return s.str();
}

}  // namespace

const DataColumn* MeasuredData::find(std::string_view name) const {
    for (const auto& c : columns)
        if (c.name == name) return &c;
    return nullptr;
}

const DataColumn& MeasuredData::at(std::string_view name) const {
    if (const auto* c = find(name)) return *c;
    throw std::invalid_argument(source + ": no column " + std::string(name));
}

std::string MeasuredData::where(std::size_t row, std::string_view column) const {
    return source + ": line " + std::to_string(lines.at(row)) + ", column " + shortened_text(column);
}

const std::vector<std::string>& reserved_columns(MeasuredKind kind) {
    static const std::vector<std::string> discharge{"geometry", "D_m",   "b_m",         "c_m",   "outlet_m",
                                                    "theta_deg", "d_p_m", "rho_b_kg_m3", "W_kg_s"};
    static const std::vector<std::string> shear{"sigma_Pa", "tau_Pa"};
    return kind == MeasuredKind::discharge ? discharge : shear;
}

namespace {
/// Spreadsheets save "CSV UTF-8" with a byte-order mark before the header; UTF-16 text cannot be read as CSV here.
void strip_byte_order_mark(std::string& first_line, const std::string& source) {
    static constexpr std::string_view utf8_bom = "\xEF\xBB\xBF";
    if (first_line.starts_with(utf8_bom)) {
        first_line.erase(0, utf8_bom.size());
        return;
    }
    if (first_line.starts_with("\xFF\xFE") || first_line.starts_with("\xFE\xFF"))
        throw std::invalid_argument(source + ": the file is UTF-16 text; save it as CSV in UTF-8 or ASCII");
}
}  // namespace

namespace {
/// A header read as one column that holds ';' or a tab: a spreadsheet set to decimal commas saves "CSV" so, and every
/// row would be refused for its field count without saying why.
void check_separator(const std::vector<std::string>& header, const std::string& source, int line_no) {
    if (header.size() != 1) return;
    for (const char separator : {';', '\t'})
        if (header.front().find(separator) != std::string::npos)
            throw std::invalid_argument(source + ": line " + std::to_string(line_no) + ": the header " +
                                        quote(header.front()) + " is one column: fields are separated by "
                                        "commas here, this file separates them by " +
                                        (separator == ';' ? "';'" : "tabs") +
                                        " (save it as CSV with ',' between fields and '.' in numbers)");
}
}  // namespace

namespace {

// The header line: one column per name, none empty or repeated (a JSON file or another separator named as such).
void read_header(MeasuredData& data, const std::vector<std::string>& fields, char first, const std::string& source,
                 int line_no) {
    if (first == '{' || first == '[')
        throw std::invalid_argument(source + ": line " + std::to_string(line_no) + " starts with '" +
                                    std::string(1, first) + "': a JSON file, not a table (CSV: a header line "
                                    "of column names, then one line per measurement)");
    check_separator(fields, source, line_no);
    // refused before the names are compared (a header of a million columns took minutes to reach this refusal)
    if (fields.size() > kMaxMeasuredColumns)
        throw std::invalid_argument(source + ": line " + std::to_string(line_no) + ": " +
                                    std::to_string(fields.size()) + " columns, more than " +
                                    std::to_string(kMaxMeasuredColumns) + " (each is a candidate effect)");
    for (const auto& name : fields) {
        if (name.empty())
            throw std::invalid_argument(source + ": line " + std::to_string(line_no) + ": empty column name");
        for (const auto& c : data.columns)
            if (c.name == name)
                throw std::invalid_argument(source + ": line " + std::to_string(line_no) + ": duplicate column " +
                                            shortened_text(name));
        data.columns.push_back(DataColumn{name, true, {}, {}});
    }
}

// Whether a column holds numbers or categories, and its numbers read: a column of mostly numbers with some text is a
// typo, not a category (e.g. "1,5" or "n/a"); a cell that reads as a number must be a usable one ("nan", "inf",
// "1e-320" are not categories).
void type_column(const MeasuredData& data, DataColumn& col) {
    std::size_t numbers = 0, texts = 0, first_text = 0;
    for (std::size_t r = 0; r < data.rows(); ++r) {
        const auto& cell = col.text[r];
        if (cell.empty()) {
            if (!may_be_empty(col.name)) throw std::invalid_argument(data.where(r, col.name) + ": missing value");
            continue;
        }
        if (const auto n = read_typed_number(cell); n.is_number && n.defect)
            throw std::invalid_argument(data.where(r, col.name) + ": " + quote(cell) + " " + *n.defect);
        if (parse_number(cell)) {
            ++numbers;
        } else if (texts++ == 0) {
            first_text = r;
        }
    }
    col.numeric = texts == 0 || (numbers >= texts && col.name != "geometry");
    if (col.numeric && texts > 0)
        throw std::invalid_argument(data.where(first_text, col.name) + ": " + quote(col.text[first_text]) +
                                    " is not a number");
    if (col.numeric) {
        col.values.reserve(data.rows());
        for (const auto& cell : col.text) col.values.push_back(cell.empty() ? nan : *parse_number(cell));
    }
}

}  // namespace

MeasuredData parse_csv(std::istream& in, const std::string& source) {
    MeasuredData data;
    data.source = source;
    std::string line;
    int line_no = 0;
    bool have_header = false;
    while (std::getline(in, line)) {
        ++line_no;
        if (line_no == 1) strip_byte_order_mark(line, source);
        const std::string t = trimmed(line);
        if (t.empty() || t[0] == '#') continue;  // blank lines and comments hold no data
        const int first_line = line_no;
        CsvRecordSplitter record;
        record.feed(line);
        for (std::string more; record.open_quote() && std::getline(in, more);) {
            ++line_no;
            record.feed("\n");
            record.feed(more);
        }
        if (record.open_quote())
            throw std::invalid_argument(source + ": line " + std::to_string(first_line) +
                                        ": unterminated quote (the quoted field runs to the end of the file)");
        const auto fields = record.finish();
        // a text that is not UTF-8 reached the JSON result only to fail there, after the diagnosis (held-back probe 65)
        for (std::size_t c = 0; c < fields.size(); ++c)
            if (!is_utf8(fields[c]))
                throw std::invalid_argument(
                    source + ": line " + std::to_string(first_line) + ", " +
                    (have_header && c < data.columns.size() ? "column " + shortened_text(data.columns[c].name)
                                                            : "field " + std::to_string(c + 1)) +
                    ": not UTF-8 text (save the file as UTF-8)");
        if (!have_header) {
            read_header(data, fields, t[0], source, first_line);
            have_header = true;
            continue;
        }
        if (fields.size() != data.columns.size())
            throw std::invalid_argument(source + ": line " + std::to_string(first_line) + ": " +
                                        std::to_string(fields.size()) + " fields, the header has " +
                                        std::to_string(data.columns.size()) +
                                        (fields.size() > data.columns.size() && data.columns.size() > 1
                                             ? " (a decimal comma, 0,105, or an unquoted comma in a text splits a "
                                               "field: numbers are written 0.105)"
                                             : ""));
        data.lines.push_back(first_line);
        for (std::size_t c = 0; c < fields.size(); ++c) data.columns[c].text.push_back(fields[c]);
    }
    if (!have_header) throw std::invalid_argument(source + ": no header line");
    if (data.rows() == 0) throw std::invalid_argument(source + ": header but no data rows");
    for (auto& col : data.columns) type_column(data, col);
    return data;
}

void validate_measured(const MeasuredData& data, MeasuredKind kind) {
    auto require_numeric = [&](const std::string& name) -> const DataColumn& {
        const auto* col = data.find(name);
        if (!col) throw std::invalid_argument(data.source + ": missing column " + name);
        if (!col->numeric) {  // only possible when most cells are text: name the first
            for (std::size_t r = 0; r < data.rows(); ++r)
                if (!parse_number(col->text[r]) && !col->text[r].empty())
                    throw std::invalid_argument(data.where(r, name) + ": " + quote(col->text[r]) + " is not a number");
        }
        return *col;
    };
    auto check = [&](std::size_t r, const DataColumn& col, bool ok, const std::string& what) {
        if (!ok) throw std::invalid_argument(data.where(r, col.name) + ": " + num(col.values[r]) + " " + what);
    };

    if (kind == MeasuredKind::shear) {
        const auto& sigma = require_numeric("sigma_Pa");
        const auto& tau = require_numeric("tau_Pa");
        for (std::size_t r = 0; r < data.rows(); ++r)
            for (const auto* col : {&sigma, &tau}) check_measured_stress(col->values[r], data.where(r, col->name));
        return;
    }

    const auto* geometry = data.find("geometry");
    if (!geometry) throw std::invalid_argument(data.source + ": missing column geometry");
    bool any_conical = false, any_rectangular = false;
    for (std::size_t r = 0; r < data.rows(); ++r) {
        const auto& g = geometry->text[r];
        if (g == "conical") any_conical = true;
        else if (g == "rectangular") any_rectangular = true;
        else
            throw std::invalid_argument(data.where(r, "geometry") + ": " + quote(g) +
                                        ", expected conical or rectangular");
    }
    const auto& outlet = require_numeric("outlet_m");
    const auto& theta = require_numeric("theta_deg");
    const auto& dp = require_numeric("d_p_m");
    const auto& rho = require_numeric("rho_b_kg_m3");
    const auto& rate = require_numeric("W_kg_s");
    const DataColumn* silo_d = any_conical ? &require_numeric("D_m") : nullptr;
    const DataColumn* depth = any_rectangular ? &require_numeric("b_m") : nullptr;
    const DataColumn* width = any_rectangular ? &require_numeric("c_m") : nullptr;
    for (const auto* col : {&outlet, &theta, &dp, &rho, &rate})
        for (std::size_t r = 0; r < data.rows(); ++r)
            if (std::isnan(col->values[r])) throw std::invalid_argument(data.where(r, col->name) + ": missing value");
    for (std::size_t r = 0; r < data.rows(); ++r) {
        check(r, dp, dp.values[r] > 0, "is not a positive particle size");
        check(r, outlet, outlet.values[r] > 0, "is not a positive outlet size");
        check(r, outlet, outlet.values[r] > dp.values[r],
              "is not larger than the particles (d_p_m = " + num(dp.values[r]) + ")");
        check(r, theta, theta.values[r] > 0 && theta.values[r] <= 90, "is not a half angle in (0, 90]");
        check(r, rho, rho.values[r] > 0, "is not a positive bulk density");
        check(r, rate, rate.values[r] > 0, "is not a positive discharge rate");
        const bool conical = geometry->text[r] == "conical";
        const auto& silo_size = conical ? *silo_d : *width;
        const std::vector<const DataColumn*> sizes =
            conical ? std::vector<const DataColumn*>{silo_d} : std::vector<const DataColumn*>{depth, width};
        for (const auto* col : sizes) {
            if (std::isnan(col->values[r]))
                throw std::invalid_argument(data.where(r, col->name) + ": missing value (needed by a " +
                                            geometry->text[r] + " silo)");
            check(r, *col, col->values[r] > 0, "is not a positive silo size");
        }
        // a size of the other shape on this row is read by no model: refused, not ignored (b_m on a conical row)
        for (const char* other : conical ? std::vector<const char*>{"b_m", "c_m"} : std::vector<const char*>{"D_m"})
            if (const DataColumn* col = data.find(other); col && !col->text[r].empty())
                throw std::invalid_argument(data.where(r, other) + ": '" + shortened_text(col->text[r]) + "' on a " +
                                            geometry->text[r] + " silo's row, where no model reads it (" +
                                            (conical ? "b_m and c_m are a rectangular silo's sizes" :
                                                       "D_m is a conical silo's diameter") +
                                            "): leave the cell empty");
        for (const auto* col : {&outlet, &dp, &rho, &rate})
            check_plausible_silo_quantity(col->name, col->values[r], data.where(r, col->name));
        for (const auto* col : sizes) check_plausible_silo_quantity(col->name, col->values[r], data.where(r, col->name));
        check(r, outlet, outlet.values[r] < silo_size.values[r],
              "is not smaller than the silo (" + silo_size.name + " = " + num(silo_size.values[r]) + ")");
    }
}

MeasuredData read_measured_csv(const std::string& path, MeasuredKind kind, std::size_t max_rows) {
    const std::string named = "data file " + shortened_text(path, 200);
    const std::string text = read_input_file(path, named, kMaxMeasuredDataBytes);
    if (text.find('\r') != std::string::npos && text.find('\n') == std::string::npos)
        throw std::invalid_argument(named + ": its lines end in CR alone (an old Mac text file); save it with LF or "
                                            "CRLF line ends");
    std::istringstream in(text);
    auto data = parse_csv(in, path);
    if (data.rows() > max_rows)
        throw std::invalid_argument(named + ": " + std::to_string(data.rows()) + " rows, more than the limit of " +
                                    std::to_string(max_rows) + " (about 2 ms of diagnosis per row; raise it with "
                                    "--max-rows)");
    validate_measured(data, kind);
    return data;
}

std::string to_csv(const MeasuredData& data) {
    std::ostringstream out;
    for (std::size_t c = 0; c < data.columns.size(); ++c) out << (c ? "," : "") << data.columns[c].name;
    out << "\n";
    for (std::size_t r = 0; r < data.rows(); ++r) {
        for (std::size_t c = 0; c < data.columns.size(); ++c) {
            const auto& col = data.columns[c];
            out << (c ? "," : "");
            if (col.numeric && !col.values.empty())
                out << (std::isnan(col.values[r]) ? std::string() : num(col.values[r]));
            else if (col.text[r].find_first_of(",\"\n\r") != std::string::npos)  // RFC 4180: these are quoted
                out << '"' << std::regex_replace(col.text[r], std::regex("\""), "\"\"") << '"';
            else
                out << col.text[r];
        }
        out << "\n";
    }
    return out.str();
}

}  // namespace demcal::analytics
