// Triangular facet walls (kernel/walls/triangle_wall.hpp): YADE's facet contact against the exact closest point, and
// the per-sphere candidate lists the kernel keeps past 64 walls (a mesh wall's facets), which must find the same
// contacts as the candidate mask, through a saved and loaded state too. The facet contact against YADE's own traces:
// test_yade_mindlin.cpp (hm_facet, hm_facet_edges).
#include <catch2/catch.hpp>

#include <algorithm>
#include <cmath>
#include <random>
#include <sstream>

#include "kernel/simulation.hpp"

using namespace demcal::kernel;

namespace {

// The exact closest point of triangle abc to p (Ericson, Real-Time Collision Detection, 5.1.5), for reference.
Vec3 closest_on_triangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0 && d2 <= 0) return a;
  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0 && d4 <= d3) return b;
  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0 && d1 >= 0 && d3 <= 0) return a + d1 / (d1 - d3) * ab;
  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0 && d5 <= d6) return c;
  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0 && d2 >= 0 && d6 <= 0) return a + d2 / (d2 - d6) * ac;
  const double va = d3 * d6 - d5 * d4;
  if (va <= 0 && (d4 - d3) >= 0 && (d5 - d6) >= 0) return b + (d4 - d3) / ((d4 - d3) + (d5 - d6)) * (c - b);
  const double denom = 1.0 / (va + vb + vc);
  return a + ab * (vb * denom) + ac * (vc * denom);
}

struct Hit {
  bool touching = false;
  Vec3 n = Vec3::Zero();
  double dn = 0, dist = 0;
};
Hit hit(const Wall& w, const Vec3& p, double r) {
  Hit h;
  h.touching = w.contact(p, r, h.n, h.dn, h.dist);
  return h;
}

}  // namespace

TEST_CASE("a triangular wall touches with its face, its edges and its vertices, on both sides", "[kernel][walls]") {
  const Vec3 a(0, 0, 0), b(0.004, 0, 0), c(0, 0.003, 0);
  const Wall w = Wall::triangle(a, b, c, 0);
  const double r = 0.001;
  // over the face, above and below
  Hit h = hit(w, Vec3(0.001, 0.001, 0.0008), r);
  REQUIRE(h.touching);
  CHECK(h.dn == Approx(0.0002).epsilon(1e-12));
  CHECK((h.n - Vec3::UnitZ()).norm() < 1e-15);
  h = hit(w, Vec3(0.001, 0.001, -0.0008), r);
  REQUIRE(h.touching);
  CHECK((h.n + Vec3::UnitZ()).norm() < 1e-15);
  // beside edge ab (y < 0), in its plane: the edge's nearest point
  h = hit(w, Vec3(0.002, -0.0006, 0.0), r);
  REQUIRE(h.touching);
  CHECK(h.dist == Approx(0.0006).epsilon(1e-12));
  CHECK((h.n + Vec3::UnitY()).norm() < 1e-12);
  // beyond vertex b: the vertex
  const Vec3 p(0.0046, -0.0004, 0.0003);
  h = hit(w, p, r);
  REQUIRE(h.touching);
  CHECK(h.dist == Approx((p - b).norm()).epsilon(1e-12));
  CHECK((h.n - (p - b).normalized()).norm() < 1e-12);
  // out of reach: over the face, and beside the hypotenuse
  CHECK_FALSE(hit(w, Vec3(0.001, 0.001, 0.0011), r).touching);
  CHECK_FALSE(hit(w, Vec3(0.004, 0.003, 0.0), r).touching);
  // a sphere over the diagonal of a flat quad made of two triangles touches both, as YADE's facets do
  const Wall other = Wall::triangle(b, Vec3(0.004, 0.003, 0), c, 0);
  const Vec3 over_diagonal = 0.5 * (b + c) + Vec3(0.00002, 0.00002, 0.0009);
  CHECK(hit(w, over_diagonal, r).touching);
  CHECK(hit(other, over_diagonal, r).touching);
}

TEST_CASE("on an acute triangle the facet contact is the exact closest point, anywhere around it", "[kernel][walls]") {
  // YADE's edge choice (the largest distance beyond an edge line) is the closest feature when no angle is obtuse
  const Vec3 a(-0.003, -0.002, 0.0005), b(0.0035, -0.0015, -0.0004), c(0.0002, 0.0036, 0.0003);
  const Wall w = Wall::triangle(a, b, c, 0);
  std::mt19937_64 rng(7);
  std::uniform_real_distribution<double> u(-0.006, 0.006);
  const double r = 0.002;
  int touching = 0, edge_or_vertex = 0;
  const Vec3 normal = (b - a).cross(c - a).normalized();
  for (int k = 0; k < 4000; ++k) {
    const Vec3 p(u(rng), u(rng), 0.3 * u(rng));
    const Vec3 q = closest_on_triangle(p, a, b, c);
    const double exact = (p - q).norm();
    const Hit h = hit(w, p, r);
    INFO("point " << p.transpose());
    REQUIRE(h.touching == (exact < r));
    if (!h.touching) continue;
    ++touching;
    CHECK(h.dist == Approx(exact).epsilon(1e-9));
    CHECK((h.n - (p - q) / exact).norm() < 1e-9);
    if (std::abs(std::abs(h.n.dot(normal)) - 1) > 1e-9) ++edge_or_vertex;
  }
  CHECK(touching > 500);
  CHECK(edge_or_vertex > 200);
}

TEST_CASE("a triangle whose vertices do not span one is refused", "[kernel][walls]") {
  CHECK_THROWS_WITH(Wall::triangle(Vec3(0, 0, 0), Vec3(1, 1, 1), Vec3(2, 2, 2), 0),
                    Catch::Contains("collinear"));
  CHECK_THROWS(Wall::triangle(Vec3(0, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), 0));
}

namespace {

const Material kGrain{1e7, 0.3, 2500, "grain"};

// Grains falling into a square funnel of four sloping facet pairs over a facet floor; `far_facets` more facets,
// far from every grain, appended after them: past 64 walls the kernel keeps a candidate list per sphere instead of a
// bit mask.
void build_funnel(Simulation& sim, int far_facets) {
  const int g = sim.add_material(kGrain);
  sim.set_pair(g, g, {{0.5}, {0.4}});
  const double h = 0.02, top = 0.012, bottom = 0.005;
  const Vec3 corner_top[4] = {{-top, -top, h}, {top, -top, h}, {top, top, h}, {-top, top, h}};
  const Vec3 corner_bottom[4] = {{-bottom, -bottom, 0}, {bottom, -bottom, 0}, {bottom, bottom, 0}, {-bottom, bottom, 0}};
  for (int k = 0; k < 4; ++k) {
    const int m = (k + 1) % 4;
    sim.add_wall(Wall::triangle(corner_bottom[k], corner_bottom[m], corner_top[m], g));
    sim.add_wall(Wall::triangle(corner_bottom[k], corner_top[m], corner_top[k], g));
  }
  sim.add_wall(Wall::triangle(corner_bottom[0], corner_bottom[1], corner_bottom[2], g));
  sim.add_wall(Wall::triangle(corner_bottom[0], corner_bottom[2], corner_bottom[3], g));
  for (int k = 0; k < far_facets; ++k) {
    const double x = 1.0 + 0.01 * k;
    sim.add_wall(Wall::triangle(Vec3(x, 0, 0), Vec3(x + 0.005, 0, 0), Vec3(x, 0.005, 0), g));
  }
  std::mt19937_64 rng(3);
  std::uniform_real_distribution<double> u(-1, 1);
  for (int k = 0; k < 60; ++k) {
    const int layer = k / 12, slot = k % 12;
    sim.add_sphere(Vec3(0.0028 * (slot % 4 - 1.5) + 0.0002 * u(rng), 0.0028 * (slot / 4 - 1) + 0.0002 * u(rng),
                        0.008 + 0.003 * layer),
                   0.001 * (1 + 0.1 * u(rng)), g, Vec3(0.05 * u(rng), 0.05 * u(rng), 0));
  }
  sim.set_timestep(0.2 * sim.rayleigh_timestep());
}

std::vector<Vec3> positions(const Simulation& sim) {
  std::vector<Vec3> x;
  for (std::size_t i = 0; i < sim.num_bodies(); ++i) x.push_back(sim.body(i).position);
  return x;
}

}  // namespace

TEST_CASE("past 64 walls the per-sphere candidate lists find the contacts the mask finds, through a saved state too",
          "[kernel][walls]") {
  Simulation masked, listed;
  build_funnel(masked, 0);
  build_funnel(listed, 70);  // 80 walls
  const long steps = 20000;  // (0.35 s: the grains fall about 1 cm and come to rest)
  masked.step(steps / 2);  // (the same chunks for all: step(a) + step(b) rounds differently from step(a + b))
  listed.step(steps / 2);
  std::stringstream state;
  listed.save_state(state);
  Simulation resumed;
  build_funnel(resumed, 70);
  resumed.load_state(state, "state");
  masked.step(steps - steps / 2);
  listed.step(steps - steps / 2);
  resumed.step(steps - steps / 2);
  // the grains settled on the facets (they touch some), and the three runs agree to the bit
  int on_walls = 0;
  for (int w = 0; w < 10; ++w) on_walls += int(masked.wall_contact_spheres(w).size());
  CHECK(on_walls > 10);
  CHECK(masked.kinetic_energy() < 1e-3 * double(masked.num_bodies()) * 2500 * 4.19e-9 * 9.81 * 0.01);  // at rest
  CHECK(positions(listed) == positions(masked));
  CHECK(positions(resumed) == positions(masked));
}

