// Output files of a silo run: the discharged mass against time (CSV) and VTK legacy snapshots for ParaView.
#pragma once
#include "kernel/silo/discharge_fit.hpp"

#include <Eigen/Core>

#include <filesystem>
#include <string>
#include <vector>

namespace demcal::kernel::silo {

// The discharge table as CSV text with header "time_s,discharged_mass_kg,discharged_grains": time since the outlet
// opened (the caller writes it atomically, beside summary.json).
struct DischargeRow {
    double time;
    double mass;
    long grains;
};
std::string discharge_csv_text(const std::vector<DischargeRow>& rows);

// One snapshot of the spheres (clump members) as VTK legacy ASCII POLYDATA: points, and point data "radius",
// "velocity" (vectors) and "clump" (the grain index).
struct SphereSnapshot {
    std::vector<Eigen::Vector3d> positions;
    std::vector<Eigen::Vector3d> velocities;
    std::vector<double> radii;
    std::vector<long> clump;
};
void write_vtk(const std::filesystem::path& file, const SphereSnapshot& s, double time);

}  // namespace demcal::kernel::silo
