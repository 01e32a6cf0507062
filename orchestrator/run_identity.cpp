#include "orchestrator/run_identity.hpp"

#include "analytics/user_input.hpp"

#include <cerrno>
#include <charconv>
#include <csignal>
#include <vector>
#include <cmath>
#include <cstdint>
#include <cstring>

#include <openssl/evp.h>

#include <fstream>
#include <sstream>
#include <stdexcept>
#include <unistd.h>

namespace demcal::orchestrator {

std::string sha256_hex(const std::string& bytes) {
    unsigned char digest[EVP_MAX_MD_SIZE];
    unsigned int len = 0;
    if (EVP_Digest(bytes.data(), bytes.size(), digest, &len, EVP_sha256(), nullptr) != 1)
        throw std::runtime_error("SHA-256 failed");
    static const char* hex = "0123456789abcdef";
    std::string out;
    for (unsigned i = 0; i < len; ++i) {
        out += hex[digest[i] >> 4];
        out += hex[digest[i] & 15];
    }
    return out;
}

namespace {
const std::string kSealHead = "{\"sha256\": \"";
const std::string kSealTail = "\", ";
constexpr std::size_t kHexDigits = 64;
}  // namespace

std::string sealed_result_text(const std::string& body) {
    if (body.empty() || body.front() != '{') throw std::invalid_argument("a result to seal must be a JSON object");
    return kSealHead + sha256_hex(body) + kSealTail + body.substr(1);
}

bool has_result_seal(const std::string& text) { return text.compare(0, kSealHead.size(), kSealHead) == 0; }

std::string unsealed_result_text(const std::string& text) {
    if (!has_result_seal(text)) return text;
    const std::size_t after = kSealHead.size() + kHexDigits + kSealTail.size();
    if (text.size() < after || text.compare(kSealHead.size() + kHexDigits, kSealTail.size(), kSealTail) != 0)
        throw DamagedResult("its seal {\"sha256\": ...} is damaged");
    const std::string recorded = text.substr(kSealHead.size(), kHexDigits);
    std::string body(1, '{');
    body.append(text, after, std::string::npos);
    const std::string actual = sha256_hex(body);
    if (actual != recorded)
        throw DamagedResult("its text does not match its SHA-256 (sealed " + recorded.substr(0, 12) + "..., the text " +
                            actual.substr(0, 12) + "...): damaged or truncated after it was written");
    return body;
}

ResultFile read_result_file(const std::filesystem::path& file, const std::string& what) {
    const std::string text = analytics::read_input_file(file, what, analytics::kMaxJsonInputBytes);
    ResultFile r;
    r.sealed = has_result_seal(text);
    try {
        r.json = analytics::parse_json_text(unsealed_result_text(text), what);
    } catch (const DamagedResult& e) {
        throw DamagedResult(what + ": " + e.what());
    }
    return r;
}

nlohmann::json read_result_json(const std::filesystem::path& file, const std::string& what) {
    ResultFile r = read_result_file(file, what);
    if (!r.sealed && r.json.is_object() && r.json.contains("schema")) {
        const nlohmann::json& schema = r.json["schema"];
        if (schema == kShearResultSchema || schema == kShearResultSchema2 || schema == kSiloSummarySchema)
            throw DamagedResult(what + ": schema " + schema.get<std::string>() +
                                " without its SHA-256 seal: damaged or not a demcal result");
    }
    return std::move(r.json);
}

namespace {
// The same number written 30000 in one material file and 30000.0 by a computed level (a double) is one run:
// integral doubles become integers before hashing (measured: a sensitivity study re-ran its base failure line
// for every parameter whose file value was an integer).
nlohmann::json canonical_numbers(const nlohmann::json& j) {
    if (j.is_object() || j.is_array()) {
        nlohmann::json out = j;
        for (auto& v : out) v = canonical_numbers(v);
        return out;
    }
    if (j.is_number_float()) {
        const double v = j.get<double>();
        if (std::isfinite(v) && std::trunc(v) == v && std::fabs(v) < 9007199254740992.0)  // 2^53: exact
            return static_cast<std::int64_t>(v);
    }
    return j;
}
}  // namespace

std::string run_identity(const std::string& template_text, const nlohmann::json& params) {
    return sha256_hex(sha256_hex(template_text) + "\n" + canonical_numbers(params).dump());
}

std::string params_digest(const nlohmann::json& params) { return sha256_hex(canonical_numbers(params).dump()); }

std::string read_text_file(const std::filesystem::path& p) {
    std::ifstream f(p, std::ios::binary);
    if (!f) throw std::runtime_error("cannot read " + p.string());
    std::ostringstream s;
    s << f.rdbuf();
    return s.str();
}

std::filesystem::path atomic_write_target(const std::filesystem::path& p) {
    namespace fs = std::filesystem;
    std::error_code ec;
    fs::path target = p;
    // a link stays a link: its target gets the new text (a rename over the link would replace the link itself)
    if (fs::is_symlink(fs::symlink_status(p, ec))) {
        target = fs::weakly_canonical(fs::absolute(p, ec), ec);
        if (ec) throw std::runtime_error("cannot write " + p.string() + " (a link that cannot be followed: " + ec.message() + ")");
    }
    // a rename over a device, a FIFO or a socket would replace the node itself (as root: /dev/null)
    const fs::file_status st = fs::status(target, ec);
    if (fs::exists(st) && !fs::is_regular_file(st))
        throw std::runtime_error("cannot write " + p.string() + ": it is " +
                                 (fs::is_directory(st) ? "a folder" : "not a regular file (a device, FIFO or socket)") +
                                 "; nothing written");
    return target;
}

void write_text_file_atomically(const std::filesystem::path& path, const std::string& text) {
    const std::filesystem::path p = atomic_write_target(path);
    std::filesystem::path tmp = p;
    tmp += ".tmp" + std::to_string(::getpid());
    {
        std::ofstream f(tmp, std::ios::binary | std::ios::trunc);
        f << text;
        f.close();
        if (!f) {
            const std::string why = std::strerror(errno);
            std::error_code ignored;
            std::filesystem::remove(tmp, ignored);  // no half-written file left behind
            throw std::runtime_error("cannot write " + p.string() + " (" + why + ")");
        }
    }
    std::error_code ec;
    std::filesystem::rename(tmp, p, ec);
    if (ec) {
        std::error_code ignored;
        std::filesystem::remove(tmp, ignored);
        throw std::runtime_error("cannot write " + p.string() + " (" + ec.message() + ")");
    }
}

}  // namespace demcal::orchestrator

namespace demcal::orchestrator {

void remove_abandoned_temporaries(const std::filesystem::path& file) {
    std::error_code ec;
    const std::filesystem::path folder = file.has_parent_path() ? file.parent_path() : ".";
    const std::string prefix = file.filename().string() + ".tmp";
    std::vector<std::filesystem::path> abandoned;
    for (std::filesystem::directory_iterator it(folder, ec), end; !ec && it != end; it.increment(ec)) {
        const std::string name = it->path().filename().string();
        if (name.compare(0, prefix.size(), prefix) != 0) continue;
        long pid = 0;
        const auto [last, bad] = std::from_chars(name.data() + prefix.size(), name.data() + name.size(), pid);
        if (bad != std::errc() || last != name.data() + name.size() || pid <= 0 || pid == ::getpid()) continue;
        if (::kill(static_cast<pid_t>(pid), 0) != 0 && errno == ESRCH) abandoned.push_back(it->path());
    }
    for (const auto& f : abandoned) std::filesystem::remove(f, ec);
}

}  // namespace demcal::orchestrator
