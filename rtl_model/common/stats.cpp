#include "rtl_model/common/stats.h"

#include <algorithm>
#include <string>

#include "traces/common/error.h"

namespace rtsim {

const StatDecl* StatBlock::find(const std::string& key) const {
    for (const StatDecl& d : stats)
        if (key == d.key) return &d;
    return nullptr;
}

const StatDecl& StatBlock::at(const std::string& key) const {
    const StatDecl* d = find(key);
    require(d != nullptr, std::string("stats: '") + path + "." + key + "' is not declared by its block");
    return *d;
}

void StatBlock::check(const nlohmann::json& j) const {
    require(j.is_object(), std::string("stats: '") + path + "' is not an object");
    for (auto it = j.begin(); it != j.end(); ++it) at(it.key());
    for (const StatDecl& d : stats)
        require(d.optional || j.contains(d.key),
                std::string("stats: '") + path + "." + d.key + "' is declared but was not written");
}

nlohmann::json StatBlock::schema_json() const {
    nlohmann::json list = nlohmann::json::array();
    for (const StatDecl& d : stats)
        list.push_back({{"key", d.key}, {"unit", d.unit}, {"meaning", d.meaning}, {"timed", d.timed},
                        {"optional", d.optional}});
    return {{"path", path}, {"stats", list}};
}

StatsWriter& StatsWriter::merge(const nlohmann::json& j) {
    for (auto it = j.begin(); it != j.end(); ++it) {
        m_block.at(it.key());
        m_out[it.key()] = it.value();
    }
    return *this;
}

StatsWriter& StatsWriter::untimed() {
    for (const StatDecl& d : m_block.stats)
        if (d.timed) m_out[d.key] = nullptr;
    return *this;
}

namespace {

std::vector<const StatBlock& (*)()>& stat_block_fns() {
    static std::vector<const StatBlock& (*)()> fns;
    return fns;
}

}  // namespace

bool register_stat_block(const StatBlock& (*block)()) {
    stat_block_fns().push_back(block);
    return true;
}

std::vector<const StatBlock*> registered_stat_blocks() {
    std::vector<const StatBlock*> out;
    for (auto fn : stat_block_fns()) out.push_back(&fn());
    std::sort(out.begin(), out.end(), [](const StatBlock* a, const StatBlock* b) {
        return std::string(a->path) < std::string(b->path);
    });
    return out;
}

const StatBlock& registered_stat_block(const std::string& path) {
    for (auto fn : stat_block_fns())
        if (path == fn().path) return fn();
    throw Error("stats: no block '" + path + "' is registered");
}

void require_optional_stat(const char* path, const StatDecl& d) {
    require(d.optional, std::string("stats: '") + path + "." + d.key + "' is declared but its source gave no value");
}

StatBlock merged_block(const char* path, const std::vector<const StatBlock*>& parts) {
    StatBlock out{path, {}};
    for (const StatBlock* b : parts) {
        if (!b) continue;
        for (const StatDecl& d : b->stats) {
            require(out.find(d.key) == nullptr, std::string("stats: '") + path + "." + d.key + "' is declared twice");
            out.stats.push_back(d);
        }
    }
    return out;
}

const nlohmann::json& StatsReader::operator[](const char* key) const {
    static const nlohmann::json null_value;
    const StatDecl& d = m_block.at(key);
    auto it = m_json.find(key);
    if (it != m_json.end()) return *it;
    require(d.optional, std::string("stats: '") + m_block.path + "." + key + "' is declared but missing");
    return null_value;
}

}  // namespace rtsim
