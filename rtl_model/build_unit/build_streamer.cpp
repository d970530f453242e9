// A build beside the traversal (build_streamer.h).
#include "rtl_model/build_unit/build_streamer.h"

#include <algorithm>

namespace rtsim {

BuildStreamer::BuildStreamer(sc_core::sc_module_name name, BuildUnit& unit) : sc_core::sc_module(name), m_unit(unit) {
    SC_THREAD(run);
}

void BuildStreamer::start(const std::vector<BuildJob>& jobs, Cycle at) {
    m_unit.begin(jobs, at);
    m_started.notify(sc_core::SC_ZERO_TIME);
}

FrameBuild BuildStreamer::finish() { return m_unit.finish(); }

void BuildStreamer::run() {
    for (;;) {
        const Cycle now = sc_core::sc_time_stamp().value();
        m_unit.issue_until(now);
        if (!m_unit.has_requests()) {  // idle, or issued in full: until the next build starts
            wait(m_started);
            continue;
        }
        const Cycle next = m_unit.next_issue();
        // Asleep until the next request is due (after `now`: issue_until issued the rest), or
        // until a build finished at a barrier (finish) and a new one started.
        wait(sc_core::sc_time::from_value(std::max<Cycle>(1, next - now)), m_started);
    }
}

}  // namespace rtsim
