#include "analytics/user_input.hpp"

#include "analytics/number_text.hpp"

#include <fstream>
#include <iterator>
#include <set>
#include <vector>

namespace demcal::analytics {

namespace fs = std::filesystem;

std::string read_input_file(const fs::path& file, const std::string& what, std::size_t max_bytes) {
    std::error_code ec;
    const auto status = fs::status(file, ec);
    if (!fs::exists(status)) throw InputError(what + " does not exist");
    if (fs::is_directory(status)) throw InputError(what + " is a folder, not a file");
    if (!fs::is_regular_file(status)) throw InputError(what + " is not a regular file");
    const auto size = fs::file_size(file, ec);
    if (ec) throw InputError(what + " cannot be read: " + ec.message());
    if (size > max_bytes)
        throw InputError(what + " has " + std::to_string(size) + " bytes, more than the limit of " +
                         std::to_string(max_bytes) + " bytes for this input");
    std::ifstream in(file, std::ios::binary);
    if (!in) throw InputError(what + " cannot be read");
    std::string text(static_cast<std::size_t>(size), '\0');
    in.read(text.data(), static_cast<std::streamsize>(size));
    if (static_cast<std::size_t>(in.gcount()) != size) throw InputError(what + " cannot be read (it changed)");
    return text;
}

std::string json_value_text(const nlohmann::json& value) {
    // a value from parse_json_text nests at most kMaxJsonDepth deep, so dump() does not recurse without bound
    return shortened_text(value.dump(-1, ' ', false, nlohmann::json::error_handler_t::replace));
}

namespace {

// Where the parser is: one frame per open object or array, for the depth limit, duplicate keys and field names.
class JsonRules {
public:
    explicit JsonRules(const std::string& what) : what_(what) {}

    bool operator()(int /*depth*/, nlohmann::json::parse_event_t event, nlohmann::json& parsed) {
        using E = nlohmann::json::parse_event_t;
        after_key_ = event == E::key;
        switch (event) {
            case E::object_start:
            case E::array_start:
                if (frames_.size() >= static_cast<std::size_t>(kMaxJsonDepth))
                    refuse("nests deeper than " + std::to_string(kMaxJsonDepth) + " levels");
                frames_.push_back({event == E::object_start, {}, {}, 0});
                break;
            case E::key: {
                Frame& f = frames_.back();
                f.key = parsed.get<std::string>();
                if (!f.keys.insert(f.key).second) refuse("appears twice in the same object");
                break;
            }
            case E::object_end:
            case E::array_end:
                frames_.pop_back();
                next_element();
                break;
            case E::value:
                if (parsed.is_number_float())
                    if (const auto defect = number_defect(parsed.get<double>()))
                        refuse("= " + json_value_text(parsed) + " " + *defect);
                next_element();
                break;
        }
        return true;
    }

    // Where a parse error was met, for its message: in the value of the key just read (a number too large, a NaN or
    // hex literal: the field is named as for a value out of range), else after the last field read.
    std::string where_failed() const {
        if (frames_.empty()) return "";
        if (after_key_) return field() + ": ";
        // in an array the failing token may end the element before the counted one ("[1, 0x10]": 0 was read): the
        // array is named, not an index
        if (!frames_.back().object) return "in " + field(false) + ": ";
        return "after " + field() + ": ";
    }

private:
    struct Frame {
        bool object;
        std::set<std::string> keys;
        std::string key;
        std::size_t index;
    };
    std::string what_;
    std::vector<Frame> frames_;
    bool after_key_ = false;  // the last event was a key: what follows is its value

    void next_element() {
        if (!frames_.empty() && !frames_.back().object) ++frames_.back().index;
    }

    // `last_index`: with the index of the element being read when the innermost frame is an array
    std::string field(bool last_index = true) const {
        std::string path;
        for (std::size_t i = 0; i < frames_.size(); ++i) {
            const Frame& f = frames_[i];
            if (f.object)
                path += (path.empty() ? "" : ".") + f.key;
            else if (last_index || i + 1 < frames_.size())
                path += "[" + std::to_string(f.index) + "]";
        }
        return path.empty() ? "the top-level value" : "field '" + shortened_text(path) + "'";
    }

    [[noreturn]] void refuse(const std::string& rule) const { throw InputError(what_ + ": " + field() + " " + rule); }
};

// nlohmann's messages start with its own tag ("[json.exception.parse_error.101] "), which names the library's
// exception class, not anything in the user's file
std::string without_library_tag(std::string message) {
    if (message.rfind("[json.exception.", 0) == 0)
        if (const auto end = message.find("] "); end != std::string::npos) message.erase(0, end + 2);
    return message;
}

}  // namespace

nlohmann::json parse_json_text(std::string_view text, const std::string& what) {
    // the parser stops at a NUL as at the end of the text: what follows would be ignored, not refused
    if (const auto nul = text.find('\0'); nul != std::string_view::npos)
        throw InputError(what + ": byte " + std::to_string(nul + 1) + " is a NUL byte: not JSON text");
    JsonRules rules(what);
    try {
        return nlohmann::json::parse(text.begin(), text.end(), std::ref(rules));
    } catch (const nlohmann::json::exception& e) {  // bad syntax, or a number too large for a double
        throw InputError(what + " is not valid JSON: " + rules.where_failed() +
                         shortened_text(without_library_tag(e.what()), 200));
    }
}

nlohmann::json read_json_input(const fs::path& file, const std::string& field) {
    const std::string what = field + " = '" + shortened_text(file.string(), 200) + "'";
    return parse_json_text(read_input_file(file, what, kMaxJsonInputBytes), what);
}

}  // namespace demcal::analytics
