// YADE's Hertz-Mindlin as yade_scripts/silo.py uses it (YadeHertzMindlin: Ip2_FrictMat_FrictMat_MindlinPhys with
// betan = betas, Law2_ScGeom_MindlinPhys_Mindlin) against YADE's own single-contact trace (tests/data/yade_contact/
// hm_pair: two unlike spheres through approach, sliding, rolling, twist and a separation fast enough that the damping
// would pull; hm_facet: a sphere on one of silo.py's wall facets through the same kinds of motion). The kernel's
// default Hertz-Mindlin (EDEM / LIGGGHTS) on the same path is not YADE's: the test also says by how much, so that it
// can tell the two apart.
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>

#include "kernel/simulation.hpp"
#include "yade_trace.hpp"

using namespace demcal::kernel;
using namespace demcal::test::yade_trace;

namespace {

double friction_of(const json& a, const json& b) {
  return std::tan(std::min(a["friction_angle"].get<double>(), b["friction_angle"].get<double>()));
}

// silo.py's betan = sqrt(5/6) |beta(e)| is the kernel's restitution e: the trace's betan back to e.
double restitution_of(const json& p) {
  const double b = p["betan"].get<double>() / std::sqrt(5.0 / 6.0);  // |beta| = -ln e / sqrt(ln^2 e + pi^2)
  return std::exp(-M_PI * b / std::sqrt(1.0 - b * b));
}

template <class Law>
double replay_hm(const std::string& name) {
  const double e = restitution_of(read_params(name));
  return replay<Law>(name, [e](const json& a, const json& b) {
    typename Law::Params p;
    p.restitution = e;
    p.friction = friction_of(a, b);
    return p;
  });
}

// YADE's law replays the trace to 1e-6; EDEM's Hertz-Mindlin (total tangential displacement, harmonic shear mixing,
// attractive damping) is another law, and the same replay tells it apart.
void check_only_yade_law_matches(const std::string& trace) {
  const double yade_law = replay_hm<YadeHertzMindlin>(trace);
  INFO(trace << ": YadeHertzMindlin's max relative error " << yade_law);
  CHECK(yade_law < 1e-6);
  const double edem_law = replay_hm<HertzMindlin>(trace);
  INFO(trace << ": HertzMindlin's max relative error " << edem_law);
  CHECK(edem_law > 1e-2);
}

}  // namespace

TEST_CASE("YADE Hertz-Mindlin: a prescribed contact of two unlike spheres gives YADE's forces and torques to 1e-6",
          "[kernel][yade-laws][yade-mindlin]") {
  CHECK(restitution_of(read_params("hm_pair")) == Approx(0.5).epsilon(1e-12));
  check_only_yade_law_matches("hm_pair");
}

TEST_CASE("YADE Hertz-Mindlin: a sphere on one of silo.py's wall facets gives YADE's force and torque to 1e-6",
          "[kernel][yade-laws][yade-mindlin]") {
  // the kernel's wall contact on YadeHertzMindlin (R* = r, m* = the sphere's mass) against Ig2_Facet_Sphere_ScGeom
  // with hertzian facets (R* = r / (1 + 1e-8)): approach, slide with spin, slide back rolling, press, fast lift-off
  check_only_yade_law_matches("hm_facet");
}

TEST_CASE("YADE Hertz-Mindlin: a sphere driven off a facet across its edges and past a vertex gives YADE's forces to 1e-6",
          "[kernel][yade-laws][yade-mindlin][walls]") {
  // the kernel's triangular wall (YADE's facet geometry: face, edge and vertex contacts, kernel/walls/triangle_wall.hpp)
  // on a facet smaller than the sphere, as silo.py's are: face, vertex (lost and found again), edge, lost, edge, face,
  // lift-off; the contact starts and ends where YADE's does (the replay checks each sampled step's contact state)
  check_only_yade_law_matches("hm_facet_edges");
}
