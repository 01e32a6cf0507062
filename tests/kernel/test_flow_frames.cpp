// The frames file another code writes for the kernel's flow-pattern classifier (kernel/silo/flow_frames.hpp): read
// frames classify exactly as the same frames given to the classifier directly, only the frames the kernel would have
// gathered count, and a damaged file is refused whole (nothing reaches the classifier), never a crash.
#include "kernel/silo/flow_frames.hpp"
#include "fuzz_mutations.hpp"

#include <catch2/catch.hpp>

#include <cmath>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <limits>
#include <string>
#include <vector>

using namespace demcal::kernel::silo;
namespace fs = std::filesystem;

namespace {

struct TestFrame {
    double time = 0, mass = 0;
    std::vector<Eigen::Vector3d> positions, velocities;
};

template <class T>
void put(std::string& bytes, T value) {
    char b[sizeof(T)];
    std::memcpy(b, &value, sizeof(T));
    bytes.append(b, sizeof(T));
}

// The format as the header documents it (the test's own writer, independent of the reader).
std::string frames_bytes(const std::vector<TestFrame>& frames) {
    std::string bytes = std::string(kFlowFramesSchema) + "\n";
    for (const auto& f : frames) {
        put(bytes, f.time);
        put(bytes, f.mass);
        put(bytes, std::uint32_t(f.positions.size()));
        for (std::size_t i = 0; i < f.positions.size(); ++i)
            for (double v : {f.positions[i].x(), f.positions[i].y(), f.positions[i].z(), f.velocities[i].z()})
                put(bytes, float(v));
    }
    return bytes;
}

fs::path write_bytes(const std::string& name, const std::string& bytes) {
    const fs::path file = fs::temp_directory_path() / ("demcal_test_flow_frames_" + name);
    std::ofstream(file, std::ios::binary).write(bytes.data(), std::streamsize(bytes.size()));
    return file;
}

// Grains across the hopper of `g`, every value exact in float; wall-layer grains move at wall_factor x the core's speed.
TestFrame hopper_frame(const SiloGeometry& g, double time, double mass, double wall_factor) {
    TestFrame f{time, mass, {}, {}};
    const double th = g.half_angle_deg * M_PI / 180;
    for (double z = 0.00390625; z < g.hopper_height(); z += 0.00390625)
        for (double s = 0.0; s < g.half_size_at(z); s += 0.001953125) {
            const bool wall = (g.half_size_at(z) - s) * std::cos(th) <= 0.0055;
            f.positions.emplace_back(float(s), 0.0, float(z));
            f.velocities.emplace_back(0.0, 0.0, wall ? -0.25 * wall_factor : -0.25);
        }
    return f;
}

}  // namespace

TEST_CASE("frames read from a file classify as the same frames given to the classifier", "[silo][flow_frames]") {
    const auto g = SiloGeometry::conical(30);
    const double filled = 0.5, lower = 0.2, upper = 0.8;
    for (const double wall_factor : {0.875, 0.375, 0.0625}) {
        // frames at 5 %, 15 %, ..., 75 % discharged; the one at 5 % lies below the gathering window (10 %)
        std::vector<TestFrame> frames;
        for (int k = 0; k < 8; ++k) frames.push_back(hopper_frame(g, 0.01 * k, filled * (0.05 + 0.1 * k), wall_factor));
        const fs::path file = write_bytes("good", frames_bytes(frames));
        FlowPatternClassifier from_file(g), direct(g);
        const FlowFramesRead read = read_flow_frames(file, filled, lower, upper, from_file);
        CHECK(read.frames_in_file == 8);
        CHECK(read.frames_gathered == 7);
        for (const auto& f : frames)
            if (gathers_frame(f.mass / filled, lower, upper)) direct.add_frame(f.positions, f.velocities, f.mass);
        const double final_mass = 0.7 * filled;
        const auto a = from_file.result(lower * final_mass, upper * final_mass);
        const auto b = direct.result(lower * final_mass, upper * final_mass);
        REQUIRE(b.pattern != FlowPattern::undetermined);
        CHECK(a.pattern == b.pattern);
        CHECK(a.ratio == b.ratio);  // the same numbers in the same order: the same bits
        CHECK(a.frames == b.frames);
        CHECK(a.wall_samples == b.wall_samples);
        CHECK(a.ratio == Approx(wall_factor).epsilon(1e-6));
    }
}

TEST_CASE("a damaged frames file is refused whole, naming the file", "[silo][flow_frames]") {
    const auto g = SiloGeometry::conical(30);
    std::vector<TestFrame> frames = {hopper_frame(g, 0.0, 0.1, 1.0), hopper_frame(g, 0.01, 0.2, 1.0)};
    const std::string good = frames_bytes(frames);
    auto refused = [&](const std::string& name, const std::string& bytes, const std::string& says) {
        FlowPatternClassifier c(g);
        INFO(name);
        try {
            read_flow_frames(write_bytes(name, bytes), 1.0, 0.2, 0.8, c);
            FAIL("accepted");
        } catch (const std::invalid_argument& e) {
            CHECK_THAT(e.what(), Catch::Contains("demcal_test_flow_frames_" + name));
            CHECK_THAT(e.what(), Catch::Contains(says));
        }
        CHECK(c.result().frames == 0);  // nothing of the good first frame reached the classifier
    };
    refused("header", "demcal.silo_frames/9\n" + good.substr(good.find('\n') + 1), "is not a demcal.silo_frames/1");
    const std::size_t second_frame_at = good.find('\n') + 1 + 20 + frames[0].positions.size() * 16;
    refused("truncated", good.substr(0, second_frame_at + 10), "truncated in frame 2 (discharged mass)");
    refused("short", good.substr(0, good.size() - 3), "grains, more than the file holds");
    std::string huge = good;
    const std::size_t count_at = good.find('\n') + 1 + 16;
    std::uint32_t big = 0xFFFFFFFFu;
    std::memcpy(huge.data() + count_at, &big, 4);
    refused("count", huge, "more than the file holds");
    frames[1].velocities[3].z() = std::numeric_limits<double>::quiet_NaN();
    refused("nan", frames_bytes(frames), "grain 4: a value is not finite");
    frames[1].velocities[3].z() = -0.25;
    frames[1].mass = 2.0;
    refused("mass", frames_bytes(frames), "outside [0, the filled mass");
    frames[1].mass = 0.2;
    frames[1].time = -1;
    refused("time", frames_bytes(frames), "runs back");
    FlowPatternClassifier c(g);
    CHECK_THROWS_AS(read_flow_frames(fs::temp_directory_path(), 1.0, 0.2, 0.8, c), std::invalid_argument);
    CHECK_THROWS_AS(read_flow_frames(fs::temp_directory_path() / "demcal_no_such_frames", 1.0, 0.2, 0.8, c),
                    std::invalid_argument);
}

TEST_CASE("fuzz: the frames reader reads or refuses every mutation", "[silo][flow_frames][fuzz][input]") {
    const auto g = SiloGeometry::conical(30);
    const std::string valid = frames_bytes({hopper_frame(g, 0.0, 0.1, 0.5), hopper_frame(g, 0.01, 0.2, 0.5)});
    int accepted = 0, refused = 0;
    for (std::uint32_t seed = 1; seed <= 2000; ++seed) {
        FlowPatternClassifier c(g);
        try {
            read_flow_frames(write_bytes("fuzz", demcal::test::mutated(valid, seed)), 1.0, 0.2, 0.8, c);
            ++accepted;
        } catch (const std::invalid_argument&) {
            ++refused;
        }
    }
    CHECK(accepted + refused == 2000);
    CHECK(refused > 1000);
}
