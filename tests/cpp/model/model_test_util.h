#pragma once
// Helpers shared by the model's module tests: a fresh SystemC kernel per test (ports are bound
// at elaboration, which SystemC does once per kernel) and a fake next memory level.
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <systemc>

#include "tests/cpp/error_of.h"
#include "rtl_model/common/interfaces.h"
#include "traces/common/error.h"

namespace rtsim::test {

/// Gives a test its own SystemC kernel (simulation context), so it can build a small testbench,
/// bind its ports and elaborate it without sc_start (SystemC elaborates once per kernel, and
/// sc_start runs once per process). The previous kernel is left alone: the modules of earlier
/// tests are gone, and SystemC has no supported way to delete a kernel.
class TestKernel {
public:
    TestKernel() {
        sc_core::sc_curr_simcontext = new sc_core::sc_simcontext;
        sc_core::sc_default_global_context = sc_core::sc_curr_simcontext;
    }
    /// Completes port binding (end of elaboration); modules are built and bound before this.
    void elaborate() { sc_core::sc_get_curr_simcontext()->elaborate(); }
};

/// A next memory level with a fixed latency that records every request it sees.
class FakeMemory : public sc_core::sc_module, public MemIf {
public:
    FakeMemory(sc_core::sc_module_name name, Cycle latency) : sc_core::sc_module(name), m_latency(latency) {}
    Cycle access(const MemRequest& req) override {
        requests.push_back(req);
        return req.time + m_latency;
    }
    std::vector<MemRequest> requests;

private:
    Cycle m_latency;
};

}  // namespace rtsim::test
