// A timed replay of rtsim's DRAM request stream in Ramulator 2.1 (scripts/dram_compare.py builds
// it against the user's own Ramulator 2 build; rtsim neither vendors nor links Ramulator).
// Ramulator 2.1's stock trace frontends send requests as fast as the controller takes them; this
// driver sends each request at its own time instead, through the External frontend that gem5's
// wrapper uses (resources/gem5_wrappers/ramulator2.cc in Ramulator's tree), so the controller
// sees the load rtsim's did.
//
//   ramulator2_driver CONFIG.json TRACE CORE_GHZ OUT.json STATS.yaml
//
// TRACE: `0xADDR READ|WRITE CYCLE` lines in issue order (rtsim-sim --dram-trace,
// dram_trace.dramsim3.txt), CYCLE in core cycles at CORE_GHZ. The memory system is ticked every
// tCK; a request is offered on the first tick at or after its time and, while the controller's
// queue is full, on every later tick (its wait counts in its latency). OUT.json: reads, writes,
// the mean read latency in ns from the request's own time to its data, the window from the first
// request to the last completion, the bytes moved; STATS.yaml: Ramulator's own statistics.
#include <cinttypes>
#include <cstdio>
#include <deque>
#include <fstream>
#include <iostream>
#include <sstream>
#include <string>

#include "ramulator/base/config.h"
#include "ramulator/base/factory.h"
#include "ramulator/base/request.h"
#include "ramulator/frontend/i_frontend.h"
#include "ramulator/memory_system/i_memory_system.h"

namespace {

struct Pending {
    uint64_t addr;
    bool write;
    double ns;  // the request's own time
};

}  // namespace

int main(int argc, char** argv) {
    if (argc != 6) {
        std::cerr << "usage: ramulator2_driver CONFIG.json TRACE CORE_GHZ OUT.json STATS.yaml\n";
        return 2;
    }
    std::ifstream cfg(argv[1]);
    std::stringstream text;
    text << cfg.rdbuf();
    Ramulator::ConfigNode config = Ramulator::Config::parse_config_string(text.str());
    Ramulator::IFrontEnd* frontend = Ramulator::Factory::create_frontend(config);
    Ramulator::IMemorySystem* memory = Ramulator::Factory::create_memory_system(config);
    frontend->connect_memory_system(memory);
    memory->connect_frontend(frontend);

    const double ghz = std::stod(argv[3]);
    std::deque<Pending> queue;
    std::ifstream trace(argv[2]);
    std::string addr, op;
    uint64_t cycle = 0;
    while (trace >> addr >> op >> cycle) queue.push_back({std::stoull(addr, nullptr, 16), op == "WRITE", double(cycle) / ghz});
    if (queue.empty()) {
        std::cerr << argv[2] << ": no requests\n";
        return 2;
    }
    const double tck = memory->get_tCK();  // ns
    const int line = memory->get_tx_bytes();
    const double first_ns = queue.front().ns;
    uint64_t reads = 0, writes = 0, done_reads = 0;
    double latency_sum = 0, last_done = first_ns;
    uint64_t tick = uint64_t(first_ns / tck);
    const uint64_t total = queue.size();
    while (!queue.empty() || done_reads < reads) {
        const double now = double(tick) * tck;
        while (!queue.empty() && queue.front().ns <= now) {
            const Pending p = queue.front();
            const bool sent = frontend->receive_external_requests(
                p.write ? Ramulator::Request::Type::Write : Ramulator::Request::Type::Read, Ramulator::Addr_t(p.addr), 0,
                [&, start = p.ns](Ramulator::Request&) {
                    const double at = double(tick) * tck;
                    latency_sum += at - start;
                    last_done = std::max(last_done, at);
                    ++done_reads;
                },
                line);
            if (!sent) break;  // the controller's queue is full: offered again next tick
            (p.write ? writes : reads) += 1;
            if (p.write) last_done = std::max(last_done, now);
            queue.pop_front();
        }
        memory->tick();
        ++tick;
        if (tick > uint64_t(first_ns / tck) + 1000000000ull) {
            std::cerr << "ramulator2_driver: no progress after 1e9 memory cycles\n";
            return 1;
        }
    }
    frontend->finalize();
    memory->finalize();
    std::ofstream stats(argv[5]);
    frontend->print_stats(stats);
    memory->print_stats(stats);
    std::ofstream out(argv[4]);
    out << "{\"requests\": " << total << ", \"reads\": " << reads << ", \"writes\": " << writes
        << ", \"mean_read_latency_ns\": " << (reads ? latency_sum / double(reads) : 0.0)
        << ", \"first_ns\": " << first_ns << ", \"last_ns\": " << last_done << ", \"bytes\": " << total * uint64_t(line)
        << ", \"tck_ns\": " << tck << "}\n";
    return 0;
}
