// Plots of particle enlargement in the manner of the seed's figures 3.4-3.6 (gnuplot, PNG or SVG by extension):
// each writes its data beside the picture (.dat) and the gnuplot script (.gp), so a plot can be redrawn by hand.
#pragma once
#include "analytics/scaling_law.hpp"
#include "calibration/particle_enlargement.hpp"

#include <filesystem>
#include <string>
#include <vector>

namespace demcal {

// Fig. 3.6: E and nu (YADE's ks/kn) against r with E(r) = A r + B and nu(r) = C r^-D. Writes OUTPUT with the
// extension `format` and its data as OUTPUT.dat.
void plot_enlargement(const std::filesystem::path& output, const std::vector<double>& r, const std::vector<double>& e,
                      const std::vector<double>& nu, const analytics::ScalingLawFit& e_law,
                      const analytics::ScalingLawFit& nu_law, const std::string& format);

// Every file plot_enlargement(output, ..., format) writes (the data, the picture and its gnuplot files).
std::vector<std::filesystem::path> enlargement_plot_files(const std::filesystem::path& output, const std::string& format);

// Fig. 3.4: mu_b and tau_c of the base parameters against r (1 SE bars), their linear-or-constant trends, the
// reference line's values and the verification points of the laws' materials.
void plot_macro_trends(const std::filesystem::path& picture, const calibration::EnlargementStudy& study);

// Fig. 3.5: CPU time per run against r with the fitted C r^-D.
void plot_run_cost(const std::filesystem::path& picture, const calibration::EnlargementStudy& study);

}  // namespace demcal
