#include "kernel/silo/flow_frames.hpp"

#include <bit>
#include <cmath>
#include <cstdint>
#include <cstring>
#include <fstream>
#include <iterator>
#include <stdexcept>
#include <string>
#include <vector>

namespace demcal::kernel::silo {

namespace {

static_assert(std::endian::native == std::endian::little, "the frames format is little-endian; this host is not");

// The whole file in memory (bounded by its size on disk: a count can never ask for more than the file holds).
class FrameBytes {
public:
    explicit FrameBytes(const std::filesystem::path& file) : name_(file.string()) {
        std::error_code ec;
        if (!std::filesystem::is_regular_file(file, ec)) fail("is not a readable file");
        std::ifstream in(file, std::ios::binary);
        if (!in) fail("cannot be opened");
        bytes_.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
        const std::string header = std::string(kFlowFramesSchema) + "\n";
        if (bytes_.size() < header.size() || std::memcmp(bytes_.data(), header.data(), header.size()) != 0)
            fail(std::string("is not a ") + kFlowFramesSchema + " file");
        at_ = header_size_ = header.size();
    }
    bool done() const { return at_ == bytes_.size(); }
    void rewind() { at_ = header_size_; }
    std::size_t left() const { return bytes_.size() - at_; }
    template <class T>
    T take(const char* what, long frame) {
        if (left() < sizeof(T)) fail("truncated in frame " + std::to_string(frame) + " (" + what + ")");
        T v;
        std::memcpy(&v, bytes_.data() + at_, sizeof(T));
        at_ += sizeof(T);
        return v;
    }
    [[noreturn]] void fail(const std::string& why) const {
        throw std::invalid_argument("frames file '" + name_ + "' " + why);
    }

private:
    std::string name_;
    std::vector<char> bytes_;
    std::size_t at_ = 0, header_size_ = 0;
};

}  // namespace

FlowFramesRead read_flow_frames(const std::filesystem::path& file, double filled_mass, double steady_lower,
                                double steady_upper, FlowPatternClassifier& classifier) {
    if (!(filled_mass > 0) || !std::isfinite(filled_mass))
        throw std::invalid_argument("filled mass = " + std::to_string(filled_mass) + ": must be > 0 and finite");
    FrameBytes in(file);
    // Two passes over the bytes in memory: the first checks every frame, the second feeds the classifier, so a damaged
    // file adds nothing and no more than one frame's grains are held as vectors.
    FlowFramesRead read;
    for (const bool add : {false, true}) {
        in.rewind();
        read = {};
        double last_time = -INFINITY;
        std::vector<Eigen::Vector3d> positions, velocities;
        while (!in.done()) {
            const long k = read.frames_in_file + 1;
            const double time = in.take<double>("time", k), mass = in.take<double>("discharged mass", k);
            const auto n = in.take<std::uint32_t>("grain count", k);
            if (!std::isfinite(time) || time < last_time)
                in.fail("frame " + std::to_string(k) + ": time " + std::to_string(time) + " s is not finite or runs back");
            if (!std::isfinite(mass) || mass < 0 || mass > filled_mass * (1 + 1e-9))
                in.fail("frame " + std::to_string(k) + ": discharged mass " + std::to_string(mass) +
                        " kg is outside [0, the filled mass " + std::to_string(filled_mass) + " kg]");
            if (std::uint64_t(n) * 4 * sizeof(float) > in.left())
                in.fail("frame " + std::to_string(k) + ": " + std::to_string(n) + " grains, more than the file holds");
            last_time = time;
            ++read.frames_in_file;
            const bool keep = add && gathers_frame(mass / filled_mass, steady_lower, steady_upper);
            positions.clear();
            velocities.clear();
            for (std::uint32_t i = 0; i < n; ++i) {
                float v[4];
                for (float& x : v) x = in.take<float>("grain", k);
                if (!(std::isfinite(v[0]) && std::isfinite(v[1]) && std::isfinite(v[2]) && std::isfinite(v[3])))
                    in.fail("frame " + std::to_string(k) + ", grain " + std::to_string(i + 1) +
                            ": a value is not finite");
                if (keep) positions.emplace_back(v[0], v[1], v[2]), velocities.emplace_back(0.0, 0.0, v[3]);
            }
            if (keep) {
                classifier.add_frame(positions, velocities, mass);
                ++read.frames_gathered;
            }
        }
    }
    return read;
}

}  // namespace demcal::kernel::silo
