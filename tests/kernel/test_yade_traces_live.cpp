// The YADE traces the kernel's YADE laws are checked against (tests/kernel/test_yade_laws.cpp) are what real YADE
// computes today: each case is run again with the installed YADE and must give the committed CSV byte for byte.
#include <catch2/catch.hpp>

#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#include "test_files.hpp"

namespace fs = std::filesystem;

TEST_CASE("the committed single-contact traces are what real YADE computes, byte for byte", "[yade]") {
  const fs::path src = fs::path(DEMCAL_SOURCE_DIR);
  const fs::path dir = fs::temp_directory_path() / ("demcal-test-yade-traces-" + std::to_string(::getpid()));
  fs::create_directories(dir);
  for (const char* name : {"ss_bond_shear_tension", "sb_frict", "sb_dynamic_damped", "cb_clump_damped", "hm_pair",
                           "hm_facet", "hm_facet_edges"}) {
    INFO(name);
    const fs::path params = src / "tests/data/yade_contact" / (std::string(name) + ".json");
    const fs::path out = dir / (std::string(name) + ".csv");
    const std::string cmd = "cd '" + dir.string() + "' && yade -n -j1 -x '" +
                            (src / "yade_scripts/run_clean.py").string() + "' '" +
                            (src / "yade_scripts/single_contact.py").string() + "' '" + params.string() + "' '" +
                            out.string() + "' > '" + (dir / "yade.log").string() + "' 2>&1";
    const int status = std::system(cmd.c_str());
    INFO(demcal::test::read_file(dir / "yade.log"));
    REQUIRE((WIFEXITED(status) ? WEXITSTATUS(status) : -1) == 0);
    CHECK(demcal::test::read_file(out) ==
          demcal::test::read_file(src / "tests/data/yade_contact" / (std::string(name) + ".csv")));
  }
  fs::remove_all(dir);
}
