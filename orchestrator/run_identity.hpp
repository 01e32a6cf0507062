// A run's identity: SHA-256 of the template's bytes and the canonical JSON of its parameters. Two runs with the same
// identity compute the same thing, so the store computes each identity once (unless forced).
#pragma once
#include <nlohmann/json.hpp>

#include <filesystem>
#include <string>

namespace demcal::orchestrator {

std::string sha256_hex(const std::string& bytes);

// Canonical form: nlohmann's dump sorts object keys, numbers print in shortest round-trip form, and an integral
// double counts as the integer (30000.0 and 30000 are one run).
std::string run_identity(const std::string& template_text, const nlohmann::json& params);

std::string read_text_file(const std::filesystem::path& p);
// Writes via a temporary file and rename, so a reader (or a crash) never sees half a file.
void write_text_file_atomically(const std::filesystem::path& p, const std::string& text);

}  // namespace demcal::orchestrator
