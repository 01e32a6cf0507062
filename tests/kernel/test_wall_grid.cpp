// The wall candidates' broad phase (kernel/wall_grid.hpp): for any wall of any shape, displaced or not, and any
// centre, the walls it offers (after its box test) must hold every wall the exact test finds, in ascending order,
// so that the candidate lists, and every force after them, are those of a test of every wall.
#include <catch2/catch.hpp>

#include <random>
#include <vector>

#include "kernel/wall_grid.hpp"

using namespace demcal::kernel;

namespace {

Vec3 random_point(std::mt19937_64& rng, double half) {
  std::uniform_real_distribution<double> u(-half, half);
  return Vec3(u(rng), u(rng), u(rng));
}

// Walls of every shape scattered over a cube of half side 0.1 m, some displaced from where they were built.
std::vector<Wall> scattered_walls(std::mt19937_64& rng, std::vector<Vec3>& displacement) {
  std::vector<Wall> walls;
  std::uniform_real_distribution<double> size(0.002, 0.04);
  for (int k = 0; k < 60; ++k) {
    const Vec3 a = random_point(rng, 0.1);
    switch (k % 6) {
      case 0: walls.push_back(Wall::triangle(a, a + random_point(rng, 0.03), a + random_point(rng, 0.03), 0)); break;
      case 1: walls.push_back(Wall::rectangle(a, random_point(rng, 1), random_point(rng, 1), size(rng), size(rng), 0));
        break;
      case 2: walls.push_back(Wall::box(a, a + Vec3(size(rng), size(rng), size(rng)), 0)); break;
      case 3: walls.push_back(Wall::cone(a.x(), a.y(), size(rng), a.z(), 0.6, 0.05, 0)); break;
      case 4: walls.push_back(Wall::cylinder(a.x(), a.y(), size(rng), a.z(), a.z() + size(rng), 0)); break;
      default:
        if (k % 24 == 5) walls.push_back(Wall::plane(a, random_point(rng, 1), 0));  // unbounded: offered everywhere
        else walls.push_back(Wall::disk(a.x(), a.y(), size(rng), a.z(), 0));
    }
    displacement.push_back(k % 3 == 0 ? random_point(rng, 0.01) : Vec3::Zero());
    walls.back().displacement = displacement.back();
  }
  return walls;
}

}  // namespace

TEST_CASE("the wall grid offers every wall a centre touches, in ascending order", "[walls]") {
  std::mt19937_64 rng(7);
  std::vector<Vec3> displacement;
  const std::vector<Wall> walls = scattered_walls(rng, displacement);
  for (const double reach : {0.0005, 0.003, 0.02}) {
    WallGrid grid;
    grid.build(walls, displacement, reach);
    CHECK(grid.cell_count() > 1);
    long touching = 0, offered_total = 0;
    for (int trial = 0; trial < 20000; ++trial) {
      const Vec3 p = random_point(rng, 0.16);  // beyond the walls too: outside the grid
      const double r = reach * std::uniform_real_distribution<double>(0.1, 1.0)(rng);
      std::vector<int> offered;
      grid.for_each_candidate(p, [&](int w) {
        if (grid.near_box(w, p, r)) offered.push_back(w);
      });
      CHECK(std::is_sorted(offered.begin(), offered.end()));
      CHECK(std::adjacent_find(offered.begin(), offered.end()) == offered.end());
      offered_total += long(offered.size());
      for (int w = 0; w < int(walls.size()); ++w) {
        Vec3 n;
        double dn, dist;
        if (!walls[std::size_t(w)].contact(p, r, n, dn, dist)) continue;
        ++touching;
        INFO("wall " << w << " reach " << reach << " point " << p.transpose());
        CHECK(std::binary_search(offered.begin(), offered.end(), w));
      }
    }
    CHECK(touching > 100);                           // the check saw contacts of every kind
    CHECK(offered_total < 20000L * long(walls.size()) / 4);  // and the grid offered far fewer than every wall
  }
}

TEST_CASE("the wall grid without bounded walls offers the unbounded ones everywhere", "[walls]") {
  const std::vector<Wall> walls = {Wall::plane(Vec3::Zero(), Vec3::UnitZ(), 0),
                                   Wall::plane(Vec3(0, 0, 1), -Vec3::UnitZ(), 0)};
  WallGrid grid;
  grid.build(walls, {Vec3::Zero(), Vec3::Zero()}, 0.01);
  std::vector<int> offered;
  grid.for_each_candidate(Vec3(5, -3, 0.5), [&](int w) { offered.push_back(w); });
  CHECK(offered == std::vector<int>{0, 1});
}
