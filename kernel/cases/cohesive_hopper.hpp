// A cohesive powder in a small conical hopper, still or vibrating: does the bed arch over the outlet, and from which
// vibration frequency does it flow (issue 24; the seed's sections 2.1.3 and 3.6). A short case over the kernel: JKR
// spheres settle with the outlet closed, the outlet opens, and the whole bin vibrates horizontally,
// x = A sin(2 pi f t), from the opening. The cohesion is the bond number of two equal grains, Bo = F_pulloff / (m g),
// F_pulloff = 3 pi gamma R*, R* = r/2. Measured results: examples/cohesive_arch/README.md.
#pragma once
#include <functional>
#include <vector>

#include "kernel/cases/cutoff_search.hpp"

namespace demcal::kernel::cases {

struct CohesiveHopperCase {
  double bond_number = 10;       ///< F_pulloff / (m g) of two equal grains [-], >= 0
  double frequency = 0;          ///< vibration frequency [Hz] (0: still)
  double amplitude = 1.1e-4;     ///< vibration amplitude [m] (the seed's largest, 0.11 mm)
  double theta_deg = 30;         ///< hopper half angle from the vertical [deg]
  double grain_radius = 1e-3;    ///< mean grain radius [m] (+/- 10 %, uniform)
  double outlet_radius = 6e-3;   ///< [m]
  double bin_radius = 20e-3;     ///< [m]
  double young = 5e6;            ///< grains' Young modulus [Pa] (soft: the time step)
  int grains = 800;
  unsigned seed = 1;             ///< seed of the jitter of the initial lattice
  double settle = 0.4;           ///< time with the outlet closed [s]
  double window = 5.0;           ///< longest time after the opening a run lasts [s], kWindowMin..kWindowMax (it
                                 ///< ends earlier once half the mass is out or its flow stops: cutoff_search.hpp's FlowCriterion); measured
                                 ///< (examples/cohesive_arch): slow runs took 2.7-4.4 s to reach half or to stop
};

/// Throws std::invalid_argument naming the field and the value when a setting is out of range.
void validate(const CohesiveHopperCase& c);

struct CohesiveHopperOutcome {
  double discharged_fraction = 0;  ///< of the mass, within the window (the run stops once half has left)
  double discharge_s = 0;          ///< simulated time from the opening to the run's end (the window, or earlier)
  /// stop_fraction (half the mass out), flow_stopped (silo::kFlowStallTime without a grain) or time_limit (the window)
  silo::DischargeEnd end = silo::DischargeEnd::running;
  double peak_acceleration_g = 0;  ///< A (2 pi f)^2 / g
  double wall_s = 0;
  bool flows(FlowCriterion c) const { return cases::flows(c, end); }
};

CohesiveHopperOutcome run_cohesive_hopper(const CohesiveHopperCase& c);

/// Throws std::invalid_argument naming the setting when the search or the case at either end of the bracket is invalid,
/// or the window is too short for the search's criterion to see an arch (shortest_window).
void validate(const CohesiveHopperCase& c, const CutoffSearch& s);
/// The lowest frequency at which this bed flows (cutoff_search.hpp), every seed at each frequency, a run still
/// discharging at its window's end run again in the longer windows of window_ladder(c.window, s.longest_window);
/// `report` sees every run (its case holds the window it ran in).
CutoffResult find_cutoff(CohesiveHopperCase c, const CutoffSearch& s,
                         const std::function<void(const CohesiveHopperCase&, const CohesiveHopperOutcome&)>& report);

}  // namespace demcal::kernel::cases
