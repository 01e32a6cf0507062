// A run's identity: SHA-256 of the template's bytes and the canonical JSON of its parameters. Two runs with the same
// identity compute the same thing, so the store computes each identity once (unless forced).
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <stdexcept>
#include <string>

namespace demcal::orchestrator {

std::string sha256_hex(const std::string& bytes);

// Canonical form: nlohmann's dump sorts object keys, numbers print in shortest round-trip form, and an integral
// double counts as the integer (30000.0 and 30000 are one run).
std::string run_identity(const std::string& template_text, const nlohmann::json& params);

// SHA-256 of the parameters' canonical form alone. It tells which run a result belongs to: a result of schema
// demcal.shear_result/3 carries the params.json object its run read ("params", both engines), a /2 result of the
// kernel engine carried this digest ("params_sha256"); a result copied from another run's folder, even of the same
// normal stress and another seed, is then not taken for this run's.
std::string params_digest(const nlohmann::json& params);

// result.json of a shear run (schema demcal.shear_result/3; /2 had the same seal) is sealed with the SHA-256 of its
// own text, so that a file damaged after its atomic write (a flipped byte, a truncated copy) is found when the
// orchestrator reads it. The
// rule, the same for every writer (yade_scripts/shear_box.py's write_result_atomically, demcal shear-run): BODY is the
// result's JSON object as the writer serialises it, with its final newline; the file is
//     {"sha256": "<64 lowercase hex digits of SHA-256(BODY)>", <BODY without its opening brace>
// which is JSON again (one more key). A reader takes BODY back as "{" + everything after the seal and compares.
inline constexpr const char* kShearResultSchema = "demcal.shear_result/3";
// The earlier sealed schema, still read: the same fields without "params" (YADE's template recorded nothing of its
// run but its normal stress; the kernel engine recorded "params_sha256").
inline constexpr const char* kShearResultSchema2 = "demcal.shear_result/2";

// A result file whose seal is missing (where its schema needs one) or does not match its text.
struct DamagedResult : std::runtime_error {
    using std::runtime_error::runtime_error;
};

// BODY (a JSON object's text, from its '{') -> the sealed file text.
std::string sealed_result_text(const std::string& body);

// The sealed file text -> BODY, checked. A text without a seal is returned as it is (results of schema
// demcal.shear_result/1, from templates older than the seal, had none); its schema is the caller's to check.
// Throws DamagedResult when the seal does not match.
std::string unsealed_result_text(const std::string& text);
bool has_result_seal(const std::string& text);

// demcal silo's summary.json, sealed by the same rule since this schema (earlier summaries had no schema and no seal).
inline constexpr const char* kSiloSummarySchema = "demcal.silo_summary/1";

// A result file read through the one JSON reader (size, depth, repeated keys: analytics::parse_json_text) with its
// seal checked where it has one. `sealed` says whether it had one; the caller decides what an unsealed file may be.
struct ResultFile {
    nlohmann::json json;
    bool sealed = false;
};
ResultFile read_result_file(const std::filesystem::path& file, const std::string& what);

// read_result_file for any result: an object whose schema is one that is always sealed (kShearResultSchema and /2,
// kSiloSummarySchema) but carries no seal is damaged (a flipped byte in the seal itself); an unsealed file of
// another schema, or of none (older writers, YADE's silo script), is taken as it is.
// Throws DamagedResult, or analytics::InputError when the text breaks the reader's rules.
nlohmann::json read_result_json(const std::filesystem::path& file, const std::string& what);

std::string read_text_file(const std::filesystem::path& p);
// Writes via a temporary file and rename, so a reader (or a crash) never sees half a file. A symbolic link is
// followed (its target is written, the link kept); a path that is a folder, a device, a FIFO or a socket is refused
// (throws, nothing written): a rename would replace the node.
void write_text_file_atomically(const std::filesystem::path& p, const std::string& text);
// Removes what a killed writer left of `file`: FILE.tmpPID whose process is gone (a 6 MB program copy stayed).
void remove_abandoned_temporaries(const std::filesystem::path& file);
// Where write_text_file_atomically writes `p` (the link's target for a link); throws as it does.
std::filesystem::path atomic_write_target(const std::filesystem::path& p);

}  // namespace demcal::orchestrator
