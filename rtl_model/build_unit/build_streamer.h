#pragma once
// A build beside the traversal (build_unit.overlap): a process that issues the build unit's line
// requests in time, as the ray buffer's admission engine issues its reads, so the L2's MSHRs and
// the DRAM see them in time order with the units' own. A whole build issued at once (as a build
// at a barrier is, the units idle) would stamp its requests across the next frame's time and
// book the L2's MSHRs ahead of the units' requests stamped earlier.
#include <vector>

#include <systemc>

#include "rtl_model/build_unit/build_unit.h"

namespace rtsim {

class BuildStreamer : public sc_core::sc_module {
public:
    BuildStreamer(sc_core::sc_module_name name, BuildUnit& unit);
    SC_HAS_PROCESS(BuildStreamer);
    /// Starts `jobs` from cycle `at` (their requests issue as time reaches them); `jobs` must
    /// outlive the build.
    void start(const std::vector<BuildJob>& jobs, Cycle at);
    /// Issues what is left of the build now and returns what it did.
    FrameBuild finish();

private:
    void run();

    BuildUnit& m_unit;
    sc_core::sc_event m_started;
};

}  // namespace rtsim
