// A silo run checkpointed by an earlier demcal resumes in this one (issues 22/23: a campaign outlives an upgrade).
// tests/data/silo_checkpoint/format<N>/ holds a checkpoint written while it discharged by the demcal that wrote format
// N (8: before the contact law was stored; 9: before the discharge's clump rotation was), and what that demcal
// reported for the same run uninterrupted (README.md there says how both were made). Resumed here, the run must
// finish exactly as the old program finished it: the settings added since take their former values, nothing else
// changed, and the file is rewritten in this demcal's format on the way.
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

std::string head_of(const fs::path& file) {
    std::ifstream in(file, std::ios::binary);
    std::string head(400, '\0');
    in.read(head.data(), std::streamsize(head.size()));
    return head;
}

void check_resumes_as_its_writer_finished(const std::string& format) {
    const fs::path fixture = fs::path(DEMCAL_SOURCE_DIR) / "tests/data/silo_checkpoint" / format;
    const auto expected = nlohmann::json::parse(std::ifstream(fixture / "expected.json"));
    INFO(format << ", written by demcal " << expected.at("written_by").get<std::string>());
    const std::string tag = "demcal-silo-checkpoint/" + std::to_string(expected.at("format").get<int>());
    REQUIRE(head_of(fixture / "checkpoint.bin").find(tag) != std::string::npos);
    // resumed on a copy: a resumed run writes its checkpoints over the file it came from
    const fs::path dir = fs::temp_directory_path() / ("demcal-test-" + format + "-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    const fs::path file = dir / "checkpoint.bin";
    fs::copy_file(fixture / "checkpoint.bin", file, fs::copy_options::overwrite_existing);
    const SiloCaseSettings stored = read_checkpoint_settings(file.string());
    CHECK(stored.contact_law == SiloContactLaw::edem);
    CHECK(stored.discharge_clump_rotation == demcal::kernel::ClumpRotation::richardson);
    CHECK(stored.particles == expected.at("particles").get<long>());
    // checkpoints after every record interval, stopped before the end: the run's state in this demcal's format
    struct Stop {};
    CHECK_THROWS_AS(resume_silo_case(file.string(), {.threads = 1, .checkpoint_interval = 0, .wall_limit = 0, .stop_request = {}},
                                     [](const SiloProgress& p) {
                                         if (p.phase == "checkpoint") throw Stop{};
                                     }),
                    Stop);
    CHECK(head_of(file).find(tag) == std::string::npos);  // rewritten in a newer format
    CHECK(head_of(file).find("demcal-silo-checkpoint/") != std::string::npos);
    const SiloCaseResult r = resume_silo_case(file.string(), {.threads = 1, .checkpoint_interval = 1e9, .wall_limit = 0, .stop_request = {}});
    CHECK(r.sessions == 3);
    CHECK(r.steps == expected.at("steps").get<long>());
    CHECK(r.grains_discharged == expected.at("grains_discharged").get<long>());
    REQUIRE(r.fit.ok);
    CHECK(r.fit.rate == expected.at("rate_kg_s").get<double>());  // bit for bit
    CHECK(r.flow.ratio == expected.at("wall_to_axis_velocity_ratio").get<double>());
    fs::remove_all(dir);
}

}  // namespace

TEST_CASE("silo checkpoint of format 8 (an earlier demcal) resumes and finishes as that demcal finished the run",
          "[silo][checkpoint]") {
    check_resumes_as_its_writer_finished("format8");
}

TEST_CASE("silo checkpoint of format 9 (an earlier demcal) resumes and finishes as that demcal finished the run",
          "[silo][checkpoint]") {
    check_resumes_as_its_writer_finished("format9");
}
