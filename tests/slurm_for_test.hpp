// A real single-node SLURM for a test that needs one (scripts/slurm/slurm_up.sh), stopped again (slurm_down.sh) when
// the test is done with it, unless it was already up: every SLURM test starts and stops the daemons the same way, and
// a failed assertion between the two no longer leaves them running.
#pragma once
#include <cstdlib>
#include <string>

namespace demcal::test {

class SlurmForTest {
public:
    SlurmForTest()
        : already_up_(std::system("sinfo -h -o %T 2>/dev/null | grep -qE '^idle|^mixed'") == 0),
          up_(already_up_ || std::system(script("slurm_up.sh").c_str()) == 0) {}
    ~SlurmForTest() { stop(); }
    SlurmForTest(const SlurmForTest&) = delete;
    SlurmForTest& operator=(const SlurmForTest&) = delete;

    bool up() const { return up_; }
    // Stops the daemons this object started (none when SLURM was up before); the destructor does it otherwise.
    void stop() {
        if (up_ && !already_up_) std::system(script("slurm_down.sh").c_str());
        up_ = false;
    }

private:
    static std::string script(const char* name) {
        return "bash '" + std::string(DEMCAL_SOURCE_DIR) + "/scripts/slurm/" + name + "' >/dev/null";
    }
    bool already_up_;
    bool up_;
};

}  // namespace demcal::test
