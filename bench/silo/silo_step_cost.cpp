// Cost per step of the full silo case, measured from a checkpoint of it: the state a fresh clone cannot reach in
// minutes (the seed's 50,000 grains packed at rest and discharging), stepped for a fixed wall time on a copy of the
// checkpoint, so that two builds (or thread counts) can be compared on the same state, one after the other.
//
//   silo_step_cost CHECKPOINT THREADS SECONDS
//
// Prints one JSON line: steps, seconds (from the end of the load to the checkpoint written at the wall limit, that
// write included: about 1 % of a 60 s run), ms per step, sphere-steps per second, CPU cores kept busy.
#include "kernel/process_time.hpp"
#include "kernel/silo/silo_case.hpp"

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <iostream>
#include <string>
#include <unistd.h>

namespace fs = std::filesystem;
using namespace demcal::kernel::silo;

int run(int argc, char** argv) {
    if (argc != 4) {
        std::cerr << "usage: silo_step_cost CHECKPOINT THREADS SECONDS\n";
        return 2;
    }
    const fs::path source = argv[1];
    const int threads = std::stoi(argv[2]);
    const double seconds = std::stod(argv[3]);
    const fs::path dir = fs::temp_directory_path() / ("demcal-silo-step-cost-" + std::to_string(::getpid()));
    fs::create_directories(dir);
    struct RemoveDir {  // the 80 MB copy goes, whatever happens
        fs::path dir;
        ~RemoveDir() {
            std::error_code ec;
            fs::remove_all(dir, ec);
        }
    } remove_dir{dir};
    const fs::path copy = dir / "checkpoint.bin";
    fs::copy_file(source, copy);
    using clock = std::chrono::steady_clock;
    clock::time_point t0, t1;
    double c0 = 0, c1 = 0;
    long step0 = 0, step1 = 0, spheres = 0;
    const SiloCaseResult r = resume_silo_case(copy.string(), {threads, 1e9, seconds, {}}, [&](const SiloProgress& p) {
        if (p.phase == "resumed") {
            t0 = clock::now();
            c0 = demcal::kernel::process_cpu_seconds();
            step0 = p.step;
            spheres = 3 * p.grains_in_silo;  // the wheat grain is a 3-sphere clump
        } else if (p.phase == "checkpoint") {
            t1 = clock::now();
            c1 = demcal::kernel::process_cpu_seconds();
            step1 = p.step;
        }
    });
    const double s = std::chrono::duration<double>(t1 - t0).count();
    const long steps = step1 - step0;
    if (!r.suspended() || steps <= 0) {
        std::cerr << "silo_step_cost: the run did not stop at the wall limit (" << r.stop_reason << ")\n";
        return 1;
    }
    std::printf("{\"threads\": %d, \"spheres\": %ld, \"steps\": %ld, \"seconds\": %.3f, \"ms_per_step\": %.3f, "
                "\"sphere_steps_per_s\": %.4g, \"cores_busy\": %.2f}\n",
                threads, spheres, steps, s, 1e3 * s / double(steps), double(spheres) * double(steps) / s,
                (c1 - c0) / s);
    return 0;
}

int main(int argc, char** argv) {
    try {
        return run(argc, argv);
    } catch (const std::exception& e) {
        std::cerr << "silo_step_cost: " << e.what() << "\n";
        return 1;
    }
}
