// What the SLURM executor reads from SLURM's own output (orchestrator/slurm_executor.hpp): the job id sbatch prints,
// the cluster's largest array, when a task SLURM no longer lists is given up. Without a cluster: the texts are
// SLURM's (23.02, Debian 12), copied from a real one.
#include "orchestrator/slurm_executor.hpp"

#include <catch2/catch.hpp>

using namespace demcal::orchestrator;

TEST_CASE("the job id of sbatch --parsable, among the warnings sbatch prints before it", "[slurm-output]") {
    CHECK(parse_sbatch_job_id("4211\n") == 4211);
    CHECK(parse_sbatch_job_id("4211;cluster_a\n") == 4211);
    CHECK(parse_sbatch_job_id("sbatch: Warning: can't honor --ntasks-per-node set to 1 which doesn't match the "
                              "requested tasks 2 with the number of requested nodes 1. Ignoring --ntasks-per-node.\n"
                              "77\n") == 77);
    CHECK_FALSE(parse_sbatch_job_id(""));
    CHECK_FALSE(parse_sbatch_job_id("sbatch: error: Batch job submission failed: Invalid job array specification\n"));
    CHECK_FALSE(parse_sbatch_job_id("Submitted batch job 12\n"));  // not --parsable's form
    CHECK_FALSE(parse_sbatch_job_id("-5\n"));
    CHECK_FALSE(parse_sbatch_job_id("99999999999999999999999999\n"));  // not a job id (and no overflow)
}

TEST_CASE("MaxArraySize from scontrol show config, SLURM's default where it cannot be read", "[slurm-output]") {
    CHECK(parse_max_array_size("KillWait                = 30 sec\nMaxArraySize            = 1001\nMaxJobCount = 10000\n") ==
          1001);
    CHECK(parse_max_array_size("MaxArraySize            = 2\n") == 2);
    CHECK(parse_max_array_size("MaxArraySizeX = 5\n") == kSlurmDefaultMaxArraySize);
    CHECK(parse_max_array_size("MaxArraySize = lots\n") == kSlurmDefaultMaxArraySize);
    CHECK(parse_max_array_size("MaxArraySize = 0\n") == kSlurmDefaultMaxArraySize);
    CHECK(parse_max_array_size("") == kSlurmDefaultMaxArraySize);
}

TEST_CASE("a task SLURM no longer lists is given up only after a while, never while it is listed", "[slurm-output]") {
    CHECK_FALSE(task_vanished(true, 1e6));
    CHECK_FALSE(task_vanished(false, 1.0));  // between a submission and squeue's first listing, a poll's hiccup
    CHECK_FALSE(task_vanished(false, kTaskVanishedAfterS));
    CHECK(task_vanished(false, kTaskVanishedAfterS + 1));
}
