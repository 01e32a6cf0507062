// The mid-plane section coloured by vertical velocity (the seed's figure 3.7): grains whose centre lies in the slab
// |y| < half_thickness are binned onto an (x, z) grid; each cell holds the mean vertical velocity of the grains seen
// in it over the frames added.
#pragma once
#include "kernel/silo/silo_geometry.hpp"
#include "kernel/state_io.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <vector>

namespace demcal::kernel::silo {

class SectionField {
public:
    SectionField(const SiloGeometry& g, double cell, double half_thickness, double z_max);
    void add_frame(const std::vector<Eigen::Vector3d>& positions, const std::vector<Eigen::Vector3d>& velocities);
    int nx() const { return nx_; }
    int nz() const { return nz_; }
    double x0() const { return x0_; }
    double cell() const { return cell_; }
    long frames() const { return frames_; }
    // Mean vertical velocity in cell (i, k) [m/s], NaN where no grain was seen.
    double vz(int i, int k) const;
    double x_centre(int i) const { return x0_ + (i + 0.5) * cell_; }
    double z_centre(int k) const { return (k + 0.5) * cell_ + z0_; }
    // Text grid for gnuplot: "x z vz" per cell, a blank line between rows of constant x ("NaN" for empty cells).
    void write_grid(const std::filesystem::path& file) const;
    // The silo outline in the section, "x z" per point, blank line between the two sides.
    void write_outline(const std::filesystem::path& file) const;
    // Checkpoint: the sums and counts gathered so far (the grid comes from the constructor's arguments).
    void save(StateWriter& w) const;
    void load(StateReader& r);

private:
    SiloGeometry g_;
    double cell_, half_thickness_, x0_, z0_;
    int nx_, nz_;
    long frames_ = 0;
    std::vector<double> sum_;
    std::vector<long> count_;
};

}  // namespace demcal::kernel::silo
