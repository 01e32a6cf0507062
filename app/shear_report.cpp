#include "app/shear_report.hpp"

#include "app/cli_support.hpp"

#include <cmath>
#include <iomanip>
#include <iostream>
#include <sstream>

namespace demcal {

using namespace orchestrator;

void print_progress(const CampaignProgress& p) {
    if (p.event == "started") return;  // one line per finished run keeps an overnight log readable
    std::ostringstream line;
    line << "[" << std::setw(6) << duration_text(p.elapsed_s) << "] " << std::left << std::setw(11) << p.event
         << std::right;
    if (p.run) {
        line << " sigma=" << p.run->label.value("normal_stress", 0.0) << " Pa rep " << p.run->label.value("replicate", 0);
        if (p.run->state == RunState::done)
            line << "  peak " << std::setprecision(4) << p.run->result.value("peak_shear_stress", 0.0) << " Pa ("
                 << duration_text(p.run->wall_s) << ")";
        else if (!p.run->cause.empty())
            line << "  " << p.run->cause << ": " << p.run->message;
    }
    line << "  | " << p.done << "/" << p.total << " done, " << p.running << " running, " << p.failed << " failed";
    if (p.reused) line << " (" << p.reused << " reused)";
    if (p.remaining_s >= 0 && p.pending + p.running > 0) line << ", ~" << duration_text(p.remaining_s) << " left";
    std::cout << line.str() << std::endl;
}

void print_line(const char* title, const analytics::FailureLine& fl) {
    std::ios saved(nullptr);
    saved.copyfmt(std::cout);  // restored at the end: later output keeps cout's default format
    std::cout << std::fixed << std::setprecision(4) << title << ": tau = " << fl.mu_b << " sigma "
              << (fl.tau_c < 0 ? "- " : "+ ") << std::setprecision(1) << std::fabs(fl.tau_c) << " Pa\n"
              << std::setprecision(4) << "  mu_b  = " << fl.mu_b << " +/- " << fl.se_mu_b << " SE  (95% CI "
              << fl.mu_b_low << " .. " << fl.mu_b_high << "),  phi_b = " << std::setprecision(2) << fl.phi_b_deg
              << " +/- " << fl.se_phi_b_deg << " deg SE\n"
              << std::setprecision(1) << "  tau_c = " << fl.tau_c << " +/- " << fl.se_tau_c << " Pa SE  (95% CI "
              << fl.tau_c_low << " .. " << fl.tau_c_high << "),  R^2 = " << std::setprecision(4) << fl.r_squared
              << ", n = " << fl.n << "\n";
    // a friction coefficient is > 0: a slope below 0, or one whose interval holds 0, is the boxes' scatter, not a
    // bulk property (sand-scale-tiny at 4-8 kPa printed mu_b = -0.0225, phi_b = -1.29 deg, without a word)
    if (!(fl.mu_b_low > 0))
        std::cout << "  warning: the slope is not determined: its 95 % interval " << std::setprecision(4)
                  << fl.mu_b_low << " .. " << fl.mu_b_high
                  << " holds 0 or lies below it (too few runs for the scatter between them: more "
                     "replicates, stresses further apart, or a larger box)\n";
    if (fl.lack_of_fit)
        std::cout << "  lack of fit: F = " << std::setprecision(3) << fl.lack_of_fit->f_statistic << " ("
                  << fl.lack_of_fit->df_lack_of_fit << ", " << fl.lack_of_fit->df_pure_error
                  << " dof), p = " << fl.lack_of_fit->p_value
                  << (fl.lack_of_fit->p_value < 0.05 ? "  -> the line does not fit the means" : "") << "\n";
    std::cout.copyfmt(saved);
}

}  // namespace demcal
