#include "app/result_files.hpp"
#include "app/scaling_plots.hpp"

#include "app/gnuplot.hpp"

#include <iomanip>
#include <sstream>

namespace demcal {

namespace fs = std::filesystem;

std::vector<fs::path> enlargement_plot_files(const fs::path& output, const std::string& format) {
    fs::path data = output, picture = output;
    data.replace_extension(".dat");
    picture.replace_extension("." + format);
    std::vector<fs::path> files = gnuplot_files(picture);
    files.insert(files.begin(), data);
    return files;
}

void plot_enlargement(const fs::path& output, const std::vector<double>& r, const std::vector<double>& e,
                      const std::vector<double>& nu, const analytics::ScalingLawFit& e_law,
                      const analytics::ScalingLawFit& nu_law, const std::string& format) {
    const std::vector<fs::path> files = enlargement_plot_files(output, format);
    const fs::path& data = files[0];
    const fs::path& picture = files[1];
    std::ostringstream d;
    d << "# particle_radius_m young_modulus_Pa poisson_ratio\n" << std::setprecision(10);
    for (std::size_t i = 0; i < r.size(); ++i) d << r[i] << " " << e[i] << " " << nu[i] << "\n";
    write_result_file(data, d.str());
    std::ostringstream g;
    g << std::setprecision(10) << "set multiplot layout 1,2\nset xlabel 'particle radius r_p [mm]'\nunset key\n"
      << "set ylabel 'E [MPa]'\nset title 'E(r_p) = A r_p + B'\n"
      << "plot " << gnuplot_quote(data) << " using ($1*1e3):($2/1e6) with points pt 7, (" << e_law.params[0].value
      << " * x / 1e3 + " << e_law.params[1].value << ") / 1e6 with lines lw 2\n"
      << "set ylabel 'nu (YADE ks/kn)'\nset title 'nu(r_p) = C r_p^{-D}'\n"
      << "plot " << gnuplot_quote(data) << " using ($1*1e3):3 with points pt 7, " << nu_law.params[0].value
      << " * (x / 1e3)**(-(" << nu_law.params[1].value << ")) with lines lw 2\nunset multiplot\n";
    render_gnuplot(picture, g.str(), 1000, 450);
}

namespace {
fs::path data_beside(const fs::path& picture) {
    fs::path data = picture;
    return data.replace_extension(".dat");
}

// gnuplot expression of a linear-or-constant trend in x [mm]
std::string trend_expression(const analytics::ResponseShapeResult& t) {
    const auto& f = t.selected();
    std::ostringstream o;
    o << std::setprecision(10) << f.coefficients[0].value;
    if (f.degree >= 1) o << " + " << f.coefficients[1].value << " * (x / 1e3 - " << t.x_ref << ")";
    return o.str();
}
}  // namespace

void plot_macro_trends(const fs::path& picture, const calibration::EnlargementStudy& s) {
    const fs::path data = data_beside(picture);
    const fs::path verified = picture.parent_path() / (picture.stem().string() + "_verified.dat");
    std::ostringstream d, v;
    d << "# r_m mu_b se_mu_b tau_c_Pa se_tau_c_Pa (base parameters)\n" << std::setprecision(10);
    const auto row = [](std::ostream& out, double r, const analytics::FailureLine& l) {
        out << r << " " << l.mu_b << " " << l.se_mu_b << " " << l.tau_c << " " << l.se_tau_c << "\n";
    };
    for (const auto& b : s.bases) row(d, b.radius, b.line);
    v << "# r_m mu_b se_mu_b tau_c_Pa se_tau_c_Pa (the laws' materials)\n" << std::setprecision(10);
    for (const auto& x : s.verifications)
        if (x.not_run_because.empty()) row(v, x.radius, x.line);
    write_result_file(data, d.str());
    write_result_file(verified, v.str());
    const auto& ref = s.bases.front().line;
    const bool has_verified = !s.verifications.empty();
    auto panel = [&](const std::string& label, int col, double ref_value, const auto& trend) {
        std::ostringstream g;
        g << std::setprecision(10) << "set ylabel '" << label << "'\nplot " << gnuplot_quote(data) << " using ($1*1e3):"
          << col << ":" << col + 1 << " with yerrorbars pt 7 lc rgb '#08519c' title 'base parameters'";
        if (trend)
            g << ", " << trend_expression(*trend) << " with lines lw 2 lc rgb '#08519c' title '"
              << analytics::to_string(trend->shape) << " fit'";
        g << ", " << ref_value << " with lines dt 2 lc rgb 'black' title 'reference'";
        if (has_verified)
            g << ", " << gnuplot_quote(verified) << " using ($1*1e3):" << col << ":" << col + 1
              << " with yerrorbars pt 5 lc rgb '#a50f15' title 'E(r), nu(r) applied'";
        return g.str() + "\n";
    };
    std::ostringstream g;
    // offsets: the end radii's error bars off the frame
    g << "set multiplot layout 1,2 title 'Particle enlargement (error bars: 1 standard error)'\nset grid\n"
      << "set offsets graph 0.05, graph 0.05, graph 0.05, graph 0.05\n"
      << "set xlabel 'particle radius r_p [mm]'\nset key top left\n"
      << panel("mu_b [-]", 2, ref.mu_b, s.mu_b_trend) << panel("tau_c [Pa]", 4, ref.tau_c, s.tau_c_trend)
      << "unset multiplot\n";
    render_gnuplot(picture, g.str(), 1200, 500);
}

void plot_run_cost(const fs::path& picture, const calibration::EnlargementStudy& s) {
    const fs::path data = data_beside(picture);
    std::ostringstream d;
    d << "# r_m cpu_s_per_run cpu_sd wall_s_per_run particles\n" << std::setprecision(10);
    for (const auto& b : s.bases)
        if (b.cost.runs > 0)
            d << b.radius << " " << b.cost.cpu_s << " " << b.cost.cpu_sd << " " << b.cost.wall_s << " "
              << b.cost.particles << "\n";
    write_result_file(data, d.str());
    std::ostringstream g;
    g << std::setprecision(10) << "set grid\nset offsets graph 0.05, graph 0.05, 0, 0\n"
      << "set xlabel 'particle radius r_p [mm]'\nset ylabel 'time per run [s]'\n"
      << "set title 'Computing cost against particle radius'\nset key top right\nset yrange [0:*]\n"
      << "plot " << gnuplot_quote(data) << " using ($1*1e3):2:3 with yerrorbars pt 7 lc rgb '#08519c' title 'CPU', "
      << gnuplot_quote(data) << " using ($1*1e3):4 with points pt 6 lc rgb '#636363' title 'wall'";
    if (s.cpu_law)
        g << ", " << s.cpu_law->params[0].value << " * (x / 1e3)**(-(" << s.cpu_law->params[1].value
          << ")) with lines lw 2 lc rgb '#08519c' title 'C r^{-D}'";
    render_gnuplot(picture, g.str() + "\n", 800, 550);
}

}  // namespace demcal
