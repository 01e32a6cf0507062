#include "kernel/silo/silo_output.hpp"

#include <fstream>
#include <iomanip>
#include <sstream>
#include <stdexcept>

namespace demcal::kernel::silo {

std::string discharge_csv_text(const std::vector<DischargeRow>& rows) {
    std::ostringstream f;
    f << "time_s,discharged_mass_kg,discharged_grains\n" << std::setprecision(9);
    for (const auto& r : rows) f << r.time << "," << r.mass << "," << r.grains << "\n";
    return f.str();
}

void write_vtk(const std::filesystem::path& file, const SphereSnapshot& s, double time) {
    // written beside, then renamed: a run killed while writing leaves no half snapshot (a resume writes it again)
    std::filesystem::path tmp = file;
    tmp += ".tmp";
    std::ofstream f(tmp);
    if (!f) throw std::runtime_error("cannot write " + file.string());
    const size_t n = s.positions.size();
    f << "# vtk DataFile Version 3.0\ndemcal silo t = " << time << " s\nASCII\nDATASET POLYDATA\n"
      << std::setprecision(7) << "POINTS " << n << " double\n";
    for (const auto& p : s.positions) f << p.x() << " " << p.y() << " " << p.z() << "\n";
    f << "VERTICES " << n << " " << 2 * n << "\n";
    for (size_t i = 0; i < n; ++i) f << "1 " << i << "\n";
    f << "POINT_DATA " << n << "\nSCALARS radius double 1\nLOOKUP_TABLE default\n";
    for (double r : s.radii) f << r << "\n";
    f << "VECTORS velocity double\n";
    for (const auto& v : s.velocities) f << v.x() << " " << v.y() << " " << v.z() << "\n";
    f << "SCALARS clump int 1\nLOOKUP_TABLE default\n";
    for (long c : s.clump) f << c << "\n";
    f.close();
    std::error_code ec;
    if (f) std::filesystem::rename(tmp, file, ec);
    if (!f || ec) {
        std::filesystem::remove(tmp, ec);
        throw std::runtime_error("failed writing " + file.string());
    }
}

}  // namespace demcal::kernel::silo
