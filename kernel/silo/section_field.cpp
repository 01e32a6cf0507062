#include "kernel/silo/section_field.hpp"

#include <cmath>
#include <fstream>
#include <limits>
#include <stdexcept>

namespace demcal::kernel::silo {

SectionField::SectionField(const SiloGeometry& g, double cell, double half_thickness, double z_max)
    : g_(g), cell_(cell), half_thickness_(half_thickness) {
    const double half = g.top_half();
    x0_ = -half;
    z0_ = -2 * cell;  // a little below the outlet: the free-falling grains
    nx_ = std::max(1, int(std::ceil(2 * half / cell)));
    nz_ = std::max(1, int(std::ceil((z_max - z0_) / cell)));
    sum_.assign(size_t(nx_) * nz_, 0.0);
    count_.assign(size_t(nx_) * nz_, 0);
}

void SectionField::add_frame(const std::vector<Eigen::Vector3d>& pos, const std::vector<Eigen::Vector3d>& vel) {
    ++frames_;
    for (size_t n = 0; n < pos.size(); ++n) {
        const Eigen::Vector3d& p = pos[n];
        if (std::abs(p.y()) >= half_thickness_) continue;
        const int i = int(std::floor((p.x() - x0_) / cell_)), k = int(std::floor((p.z() - z0_) / cell_));
        if (i < 0 || i >= nx_ || k < 0 || k >= nz_) continue;
        sum_[size_t(k) * nx_ + i] += vel[n].z();
        ++count_[size_t(k) * nx_ + i];
    }
}

double SectionField::vz(int i, int k) const {
    const size_t c = size_t(k) * nx_ + i;
    return count_[c] ? sum_[c] / count_[c] : std::numeric_limits<double>::quiet_NaN();
}

void SectionField::write_grid(const std::filesystem::path& file) const {
    std::ofstream f(file);
    if (!f) throw std::runtime_error("cannot write " + file.string());
    f << "# x_m z_m vz_m_s (mean over " << frames_ << " frames, slab |y| < " << half_thickness_ << " m)\n";
    for (int i = 0; i < nx_; ++i) {
        for (int k = 0; k < nz_; ++k) {
            const double v = vz(i, k);
            f << x_centre(i) << " " << z_centre(k) << " ";
            if (std::isnan(v))
                f << "NaN\n";
            else
                f << v << "\n";
        }
        f << "\n";
    }
}

void SectionField::write_outline(const std::filesystem::path& file) const {
    std::ofstream f(file);
    if (!f) throw std::runtime_error("cannot write " + file.string());
    const double hh = g_.hopper_height(), top = g_.top(), r0 = g_.outlet_half(), r1 = g_.top_half();
    for (int side : {-1, 1}) {
        f << side * r0 << " 0\n" << side * r1 << " " << hh << "\n" << side * r1 << " " << top << "\n\n";
    }
    f.close();
    if (!f) throw std::runtime_error("failed writing " + file.string());
}

}  // namespace demcal::kernel::silo

namespace demcal::kernel::silo {

void SectionField::save(StateWriter& w) const {
    w.value(frames_);
    w.array(sum_);
    w.array(count_);
}

void SectionField::load(StateReader& r) {
    const std::size_t cells = sum_.size();
    r.value(frames_, "section frames");
    r.array(sum_, "section sums");
    r.array(count_, "section counts");
    if (sum_.size() != cells || count_.size() != cells) r.fail("section", "the grid differs from the run's settings");
}

}  // namespace demcal::kernel::silo
