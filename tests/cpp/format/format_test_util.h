#pragma once
// Helpers shared by the trace-format tests: a scratch folder, whole-file I/O, deterministic
// records and capturing an rtsim::Error's message.
#include <cstdint>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <functional>
#include <string>
#include <vector>

#include <unistd.h>

#include "tests/cpp/error_of.h"
#include "traces/common/error.h"
#include "traces/format/trace_format.h"

namespace rtsim::test {

/// A fresh folder under the system temp folder, removed with everything in it.
class ScratchDir {
public:
    ScratchDir() {
        static int counter = 0;
        m_path = std::filesystem::temp_directory_path() /
                 ("rtsim_format_" + std::to_string(::getpid()) + "_" + std::to_string(counter++));
        std::filesystem::remove_all(m_path);
        std::filesystem::create_directories(m_path);
    }
    ~ScratchDir() { std::filesystem::remove_all(m_path); }
    std::string file(const std::string& name) const { return (m_path / name).string(); }
    std::vector<std::string> listing() const {
        std::vector<std::string> names;
        for (const auto& e : std::filesystem::directory_iterator(m_path))
            names.push_back(e.path().filename());
        return names;
    }

private:
    std::filesystem::path m_path;
};

inline std::vector<uint8_t> read_bytes(const std::string& path) {
    std::ifstream in(path, std::ios::binary);
    return std::vector<uint8_t>(std::istreambuf_iterator<char>(in), {});
}
inline void write_bytes(const std::string& path, const std::vector<uint8_t>& bytes) {
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), bytes.size());
}

/// Record i of each kind: a pure function of i, so large traces can be checked piecewise.
inline RayRecord ray_at(uint64_t i) {
    RayRecord r{};
    for (int k = 0; k < 3; ++k) {
        r.origin[k] = float(i % 1000) * 0.5f + float(k);
        r.direction[k] = float(k == int(i % 3)) - 0.25f;
    }
    r.tmin = 1e-4f;
    r.tmax = float(i);
    r.pixel = uint32_t(i * 7);
    r.kind = uint8_t(i % 5);
    r.flags = uint8_t(i & 1);
    r.depth = uint16_t(i % 4);
    return r;
}
inline HitRecord hit_at(uint64_t i) {
    return HitRecord{int32_t(i % 11) - 1, int32_t(i / 3), float(i) * 0.25f, 0.125f, float(i % 8) / 8.0f};
}
inline WorkRecord work_at(uint64_t i) {
    return WorkRecord{uint32_t(i), uint32_t(2 * i), uint32_t(i % 17), uint32_t(i % 2), 0, uint32_t(i % 5), 0, uint32_t(i % 3)};
}

}  // namespace rtsim::test
