// libFuzzer target: the simulator's config parser as rtsim-sim uses it. The first line is the
// config JSON (config_from_json, then validate), every further line a --set assignment
// (config_set). Contract: rtsim::Error, never a crash or a sanitizer report.
#include <cstddef>
#include <cstdint>
#include <sstream>
#include <string>

#include "sim/config/config.h"
#include "traces/common/error.h"

// The unit kinds (linked in so traversal.model and their sections exist) bring SystemC, whose
// library wants an sc_main; libFuzzer's main runs instead, so this one is never called.
extern "C" int sc_main(int, char**) { return 0; }  // as <systemc> declares it

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
    std::istringstream in(std::string(reinterpret_cast<const char*>(data), size));
    std::string json_text, line;
    std::getline(in, json_text);
    try {
        nlohmann::json j = nlohmann::json::parse(json_text, nullptr, false);
        rtsim::SimConfig config = j.is_discarded() ? rtsim::SimConfig{} : rtsim::config_from_json(j);
        while (std::getline(in, line)) rtsim::config_set(config, line);
        rtsim::validate(config);
        rtsim::config_to_json(config).dump();
    } catch (const rtsim::Error&) {
    }
    return 0;
}
