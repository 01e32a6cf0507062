#include "app/execution_options.hpp"

#include "app/cli_support.hpp"
#include "kernel/cases/shear_box.hpp"

#include <filesystem>

namespace demcal {

void add_execution_options(CLI::App* cmd, orchestrator::ExecutionOptions& e) {
    // The kernel engine's runs are this very program (its path now, so a rebuild during a campaign runs the new one
    // only where the identity, which names the engine's version, says it is the same engine).
    std::error_code ec;
    const auto self = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (!ec) e.kernel_command = {self.string(), "shear-run"};
    e.kernel_engine = kernel::cases::kShearBoxEngine;
    cmd->add_option("--jobs,-j", e.jobs, "runs in parallel (0 = one per core)")
        ->check(non_negative_number())
        ->capture_default_str();
    cmd->add_option("--timeout", e.timeout_s, "per-run wall-clock limit [s]")->check(run_timeout())->capture_default_str();
    // a crash that 100 attempts did not get past is the run's, not the machine's (1e9 retried one crash forever)
    cmd->add_option("--retries", e.retries, "further attempts after a crash or timeout, at most 100")
        ->check(integer_in(0, 100))
        ->capture_default_str();
    cmd->add_option("--executor", e.executor, "local (process pool) or slurm (job arrays)")
        ->check(CLI::IsMember({"local", "slurm"}))
        ->capture_default_str();
    cmd->add_option("--partition", e.slurm_partition, "SLURM partition (slurm executor)");
    cmd->add_option("--yade", e.yade, "YADE launcher to run (a path, or a name on PATH)")->capture_default_str();
    cmd->add_option("--max-runs", e.max_runs, "most simulations this command may plan (a guard against typos)")
        ->check(integer_in(1, 1000000000))
        ->capture_default_str();
}

}  // namespace demcal
