// A silo run checkpointed by an earlier demcal resumes in this one (issue 22/23: a campaign outlives an upgrade).
// tests/data/silo_checkpoint/format9/ holds a checkpoint written by demcal at commit 9ca7adf (checkpoint format 9, the
// last before the discharge's clump rotation was stored) while it discharged, and what that demcal reported for the
// same run uninterrupted (README.md there says how both were made). Resumed here, the run must finish exactly as the
// old program finished it: the settings added since take their former values, and nothing else changed.
#include "kernel/silo/silo_case.hpp"

#include <catch2/catch.hpp>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

#include <unistd.h>

using namespace demcal::kernel::silo;
namespace fs = std::filesystem;

namespace {

const fs::path kFixtures = fs::path(DEMCAL_SOURCE_DIR) / "tests/data/silo_checkpoint";

}  // namespace

TEST_CASE("silo checkpoint of format 9 (an earlier demcal) resumes and finishes as that demcal finished the run",
          "[silo][checkpoint]") {
    const fs::path fixture = kFixtures / "format9";
    const auto expected = nlohmann::json::parse(std::ifstream(fixture / "expected.json"));
    // resumed on a copy: a resumed run writes its checkpoints over the file it came from
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-format9-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "checkpoint.bin";
    fs::copy_file(fixture / "checkpoint.bin", file, fs::copy_options::overwrite_existing);
    const SiloCaseSettings stored = read_checkpoint_settings(file.string());
    CHECK(stored.contact_law == SiloContactLaw::edem);
    CHECK(stored.discharge_clump_rotation == demcal::kernel::ClumpRotation::richardson);
    CHECK(stored.particles == expected.at("particles").get<long>());
    // (checkpoints after every record interval: the file is rewritten in this demcal's format on the way)
    const SiloCaseResult r = resume_silo_case(file.string(), {.threads = 1, .checkpoint_interval = 0});
    CHECK(r.sessions == 2);
    CHECK(r.steps == expected.at("steps").get<long>());
    CHECK(r.grains_discharged == expected.at("grains_discharged").get<long>());
    REQUIRE(r.fit.ok);
    CHECK(r.fit.rate == expected.at("rate_kg_s").get<double>());  // bit for bit
    CHECK(r.flow.ratio == expected.at("wall_to_axis_velocity_ratio").get<double>());
    // and the file it leaves is of this demcal's format, read back with the same settings
    std::ifstream in(file, std::ios::binary);
    const std::string head(400, '\0');
    in.read(const_cast<char*>(head.data()), std::streamsize(head.size()));
    CHECK(head.find("demcal-silo-checkpoint/") != std::string::npos);
    CHECK(head.find("demcal-silo-checkpoint/9") == std::string::npos);  // rewritten in a newer format
    const SiloCaseSettings rewritten = read_checkpoint_settings(file.string());
    CHECK(rewritten.particles == stored.particles);
    CHECK(rewritten.geometry.half_angle_deg == stored.geometry.half_angle_deg);
    fs::remove_all(dir);
}
