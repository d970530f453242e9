// The config tree: defaults validate, every field's range is enforced with its full key path,
// unknown keys are refused by name, JSON round-trips, and the cross-field rules hold.
#include <gtest/gtest.h>

#include <functional>

#include "sim/config/config.h"
#include "model_test_util.h"

namespace rtsim {
namespace {

using nlohmann::json;
using test::error_of;

struct Field {
    std::string path;
    json spec;
};

/// Every leaf field of the schema with its dotted key path.
std::vector<Field> schema_fields(const json& schema = config_schema(), const std::string& prefix = "") {
    std::vector<Field> out;
    for (auto it = schema.begin(); it != schema.end(); ++it) {
        const std::string path = prefix.empty() ? it.key() : prefix + "." + it.key();
        if (it.value()["type"] == "section") {
            auto inner = schema_fields(it.value()["fields"], path);
            out.insert(out.end(), inner.begin(), inner.end());
        } else {
            out.push_back({path, it.value()});
        }
    }
    return out;
}

std::string validate_error(const SimConfig& c) {
    return error_of([&] { validate(c); });
}

std::string number_text(const json& spec, double x) {
    return spec["type"] == "int" ? std::to_string(int64_t(x)) : json(x).dump();
}

TEST(Config, DefaultsValidate) {
    EXPECT_NO_THROW(validate(SimConfig{}));
    // The schema lists every field of the tree (spot checks across sections).
    std::vector<std::string> paths;
    for (const Field& f : schema_fields()) paths.push_back(f.path);
    for (const char* p : {"clock_ghz", "fidelity", "ideal_memory", "traversal.units", "box.sharing", "l1.size_kib",
                          "l2.mshrs", "dram.bytes_per_cycle", "dispatch.chunk_rays"})
        EXPECT_NE(std::find(paths.begin(), paths.end(), p), paths.end()) << p;
}

TEST(Config, EveryNumericFieldOutOfRangeIsRejectedByItsPath) {
    int numeric = 0;
    for (const Field& f : schema_fields()) {
        if (f.spec["type"] != "int" && f.spec["type"] != "float") continue;
        ++numeric;
        const double lo = f.spec["min"], hi = f.spec["max"];
        // Above the maximum.
        SimConfig above;
        config_set(above, f.path + "=" + number_text(f.spec, f.spec["type"] == "int" ? hi + 1 : hi * 2));
        std::string message = validate_error(above);
        EXPECT_NE(message.find("'" + f.path + "'"), std::string::npos) << f.path << ": " << message;
        EXPECT_NE(message.find("out of range"), std::string::npos) << f.path << ": " << message;
        // Below the minimum (where a smaller value can be written at all).
        if (lo > 0) {
            SimConfig below;
            config_set(below, f.path + "=" + number_text(f.spec, f.spec["type"] == "int" ? lo - 1 : 0.0));
            message = validate_error(below);
            EXPECT_NE(message.find("'" + f.path + "'"), std::string::npos) << f.path << ": " << message;
        }
        // The bounds themselves pass the range check (a cross-field rule may still object).
        for (double bound : {lo, hi}) {
            SimConfig at_bound;
            config_set(at_bound, f.path + "=" + number_text(f.spec, bound));
            message = validate_error(at_bound);
            EXPECT_EQ(message.find("out of range"), std::string::npos) << f.path << ": " << message;
        }
    }
    EXPECT_GE(numeric, 30);
}

TEST(Config, ChoicesAndTypesAreChecked) {
    // Choices are parsed once, when read: an unknown name is refused naming the key and the choices.
    SimConfig c;
    std::string message = error_of([&] { config_set(c, "box.sharing=maybe"); });
    EXPECT_NE(message.find("'box.sharing'"), std::string::npos) << message;
    EXPECT_NE(message.find("private, shared"), std::string::npos) << message;
    EXPECT_EQ(c.box.sharing, Sharing::per_unit);  // unchanged
    SimConfig f;
    EXPECT_NE(error_of([&] { config_set(f, "fidelity=detailed_please"); }).find("'fidelity'"), std::string::npos);
    config_set(f, "fidelity=detailed");
    EXPECT_EQ(f.fidelity, Fidelity::detailed);
    EXPECT_EQ(config_to_json(f)["fidelity"], "detailed");

    SimConfig t;
    message = error_of([&] { config_set(t, "l1.size_kib=abc"); });
    EXPECT_NE(message.find("'l1.size_kib' must be a number"), std::string::npos) << message;
    message = error_of([&] { config_set(t, "l1.size_kib=1.5"); });
    EXPECT_NE(message.find("'l1.size_kib'"), std::string::npos) << message;
    message = error_of([&] { config_set(t, "l1.size_kib=-4"); });
    EXPECT_NE(message.find("'l1.size_kib'"), std::string::npos) << message;
    message = error_of([&] { config_set(t, "ideal_memory=1"); });
    EXPECT_NE(message.find("'ideal_memory' must be true or false"), std::string::npos) << message;
    message = error_of([&] { config_set(t, "l1=4"); });
    EXPECT_NE(message.find("'l1' must be an object"), std::string::npos) << message;
    message = error_of([&] { config_set(t, "no_equals_sign"); });
    EXPECT_NE(message.find("key=value"), std::string::npos) << message;
    // A bare word for a choice needs no JSON quotes.
    config_set(t, "triangle.sharing=shared");
    EXPECT_EQ(t.triangle.sharing, Sharing::shared);
}

TEST(Config, UnknownKeysAreRejectedByName) {
    SimConfig c;
    std::string message = error_of([&] { config_set(c, "l1.sizekib=4"); });
    EXPECT_NE(message.find("unknown key 'l1.sizekib'"), std::string::npos) << message;
    EXPECT_NE(message.find("size_kib"), std::string::npos) << "lists the known keys: " << message;
    message = error_of([&] { config_set(c, "nonsense.key=1"); });
    EXPECT_NE(message.find("nonsense.key"), std::string::npos) << message;
    message = error_of([&] { config_from_json(json{{"traversal", {{"units", 4}, {"unitz", 4}}}}); });
    EXPECT_NE(message.find("unknown key 'traversal.unitz'"), std::string::npos) << message;
    message = error_of([&] { config_from_json(json{{"dram", {{"channels", 4}}}, {"Dram", json::object()}}); });
    EXPECT_NE(message.find("unknown key 'Dram'"), std::string::npos) << message;
    message = error_of([&] { config_from_json(json::array()); });
    EXPECT_NE(message.find("must be an object"), std::string::npos) << message;
}

TEST(Config, JsonRoundTrip) {
    // Every field moved off its default, then written and read back.
    SimConfig c;
    for (const Field& f : schema_fields()) {
        const json& s = f.spec;
        std::string value;
        if (s["type"] == "int") value = std::to_string(int64_t(s["max"].get<double>()));
        else if (s["type"] == "float") value = "2.5";
        else if (s["type"] == "bool") value = s["default"].get<bool>() ? "false" : "true";
        else {
            const std::string first = s["choices"].front(), last = s["choices"].back();
            value = last == s["default"].get<std::string>() ? first : last;
        }
        config_set(c, f.path + "=" + value);
    }
    const json j = config_to_json(c);
    EXPECT_NE(j, config_to_json(SimConfig{}));
    EXPECT_EQ(config_to_json(config_from_json(j)), j);
    EXPECT_EQ(config_from_json(j).traversal.units, 4096u);
    EXPECT_EQ(config_from_json(j).clock_ghz, 2.5);
    EXPECT_EQ(config_from_json(j).box.sharing, Sharing::shared);
    EXPECT_TRUE(config_from_json(j).ideal_memory);
    // A partial JSON keeps the base for the rest.
    SimConfig partial = config_from_json(json{{"l1", {{"ways", 8}}}});
    EXPECT_EQ(partial.l1.ways, 8u);
    EXPECT_EQ(partial.l1.size_kib, SimConfig{}.l1.size_kib);
    // The defaults as JSON match the schema's defaults.
    for (const Field& f : schema_fields()) {
        const json defaults = config_to_json(SimConfig{});
        const json* v = &defaults;
        for (size_t start = 0;;) {
            size_t dot = f.path.find('.', start);
            v = &v->at(f.path.substr(start, dot - start));
            if (dot == std::string::npos) break;
            start = dot + 1;
        }
        EXPECT_EQ(*v, f.spec["default"]) << f.path;
    }
}

TEST(Config, CrossFieldRules) {
    SimConfig lines;
    lines.l1.line_bytes = 128;
    std::string message = validate_error(lines);
    EXPECT_NE(message.find("'l1.line_bytes'"), std::string::npos) << message;
    EXPECT_NE(message.find("'l2.line_bytes'"), std::string::npos) << message;

    SimConfig sets;
    sets.l1.size_kib = 48;  // 768 lines of 64 B / 4 ways = 192 sets: not a power of two
    message = validate_error(sets);
    EXPECT_NE(message.find("'l1.size_kib'"), std::string::npos) << message;
    EXPECT_NE(message.find("power of two"), std::string::npos) << message;

    SimConfig ways;
    ways.l2.size_kib = 1;
    ways.l2.ways = 32;  // 16 lines cannot make one set of 32 ways
    message = validate_error(ways);
    EXPECT_NE(message.find("'l2.size_kib'"), std::string::npos) << message;

    SimConfig odd_line;
    odd_line.l1.line_bytes = odd_line.l2.line_bytes = 96;
    message = validate_error(odd_line);
    EXPECT_NE(message.find("'l1.line_bytes' must be a power of two"), std::string::npos) << message;

    SimConfig interleave;
    interleave.dram.interleave_bytes = 96;
    message = validate_error(interleave);
    EXPECT_NE(message.find("'dram.interleave_bytes'"), std::string::npos) << message;
    interleave.dram.interleave_bytes = 64;
    interleave.l1.line_bytes = interleave.l2.line_bytes = 128;
    message = validate_error(interleave);
    EXPECT_NE(message.find("'dram.interleave_bytes'"), std::string::npos) << message;

    SimConfig fine;
    fine.l1.size_kib = 32;
    fine.l1.ways = 8;
    fine.l1.line_bytes = fine.l2.line_bytes = 128;
    EXPECT_EQ(validate_error(fine), "");
}

}  // namespace
}  // namespace rtsim
