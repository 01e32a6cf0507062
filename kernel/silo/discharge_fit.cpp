#include "kernel/silo/discharge_fit.hpp"

#include <algorithm>
#include <cmath>

namespace demcal::kernel::silo {

DischargeFit fit_discharge_rate(const std::vector<DischargeSample>& samples, double reference_mass,
                                double lower_fraction, double upper_fraction) {
    DischargeFit f;
    f.lower_fraction = lower_fraction;
    f.upper_fraction = upper_fraction;
    f.reference_mass = reference_mass;
    if (!(reference_mass > 0)) {  // a window of zero mass holds every sample and fits a rate of 0 with R^2 = 1
        f.message = "nothing was discharged";
        return f;
    }
    const double lo = lower_fraction * reference_mass, hi = upper_fraction * reference_mass;
    double st = 0, sm = 0;
    double m_min = hi, m_max = lo;
    int n = 0;
    for (const auto& s : samples)
        if (s.mass >= lo && s.mass <= hi) {
            st += s.time;
            sm += s.mass;
            m_min = std::min(m_min, s.mass);
            m_max = std::max(m_max, s.mass);
            if (n == 0) f.t_begin = s.time;
            f.t_end = s.time;
            ++n;
        }
    f.n = n;
    if (n < 3) {
        f.message = "only " + std::to_string(n) + " samples between " + std::to_string(lower_fraction * 100) +
                    " % and " + std::to_string(upper_fraction * 100) + " % of the filled mass";
        return f;
    }
    const double tm = st / n, mm = sm / n;
    double stt = 0, stm = 0, smm = 0;
    for (const auto& s : samples)
        if (s.mass >= lo && s.mass <= hi) {
            stt += (s.time - tm) * (s.time - tm);
            stm += (s.time - tm) * (s.mass - mm);
            smm += (s.mass - mm) * (s.mass - mm);
        }
    if (!(stt > 0)) {
        f.message = "the samples of the steady part all have the same time";
        return f;
    }
    if (!(m_max > m_min)) {  // (not smm: the mean's rounding leaves it above 0 on a plateau)
        f.message = "the discharged mass does not change between " + std::to_string(lower_fraction * 100) + " % and " +
                    std::to_string(upper_fraction * 100) + " % of the reference mass";
        return f;
    }
    f.rate = stm / stt;
    f.intercept = mm - f.rate * tm;
    double sse = 0;
    for (const auto& s : samples)
        if (s.mass >= lo && s.mass <= hi) {
            const double e = s.mass - (f.intercept + f.rate * s.time);
            sse += e * e;
        }
    f.r_squared = 1 - sse / smm;
    f.rate_se = std::sqrt(sse / (n - 2) / stt);
    f.ok = std::isfinite(f.rate);
    // batch slopes over four equal time spans of the window (each needs 3 samples)
    constexpr int nb = 4;
    std::vector<double> slopes;
    for (int b = 0; b < nb; ++b) {
        const double t0 = f.t_begin + (f.t_end - f.t_begin) * b / nb, t1 = f.t_begin + (f.t_end - f.t_begin) * (b + 1) / nb;
        double bt = 0, bm = 0;
        int bn = 0;
        for (const auto& s : samples)
            if (s.mass >= lo && s.mass <= hi && s.time >= t0 && (s.time < t1 || (b == nb - 1 && s.time <= t1))) {
                bt += s.time;
                bm += s.mass;
                ++bn;
            }
        if (bn < 3) continue;
        bt /= bn;
        bm /= bn;
        double btt = 0, btm = 0;
        for (const auto& s : samples)
            if (s.mass >= lo && s.mass <= hi && s.time >= t0 && (s.time < t1 || (b == nb - 1 && s.time <= t1))) {
                btt += (s.time - bt) * (s.time - bt);
                btm += (s.time - bt) * (s.mass - bm);
            }
        if (btt > 0) slopes.push_back(btm / btt);
    }
    if (slopes.size() >= 2) {
        double mean = 0, var = 0;
        for (double v : slopes) mean += v;
        mean /= double(slopes.size());
        for (double v : slopes) var += (v - mean) * (v - mean);
        var /= double(slopes.size() - 1);
        f.batches = int(slopes.size());
        f.rate_batch_se = std::sqrt(var / double(slopes.size()));
    }
    return f;
}

}  // namespace demcal::kernel::silo
