// "name:key=value,key=value" specs for the generated scenes, as the command line takes them.
#include <homcull/error.hpp>
#include <homcull/generate.hpp>

#include <cerrno>
#include <cmath>
#include <cstdlib>
#include <map>
#include <string>

namespace homcull {
namespace {

std::map<std::string, std::string> parse_options(std::string_view text, std::string_view spec) {
    std::map<std::string, std::string> options;
    while (!text.empty()) {
        const std::size_t comma = text.find(',');
        const std::string_view item = text.substr(0, comma);
        const std::size_t eq = item.find('=');
        if (eq == std::string_view::npos || eq == 0 || eq + 1 == item.size())
            throw Error("generated scene '" + std::string(spec) + "': expected key=value, got '" +
                        std::string(item) + "'");
        options[std::string(item.substr(0, eq))] = std::string(item.substr(eq + 1));
        text = comma == std::string_view::npos ? std::string_view{} : text.substr(comma + 1);
    }
    return options;
}

double to_number(const std::string& key, const std::string& value, std::string_view spec) {
    char* end = nullptr;
    errno = 0;
    const double v = std::strtod(value.c_str(), &end);
    if (end == value.c_str() || *end != '\0' || errno != 0 || !std::isfinite(v))
        throw Error("generated scene '" + std::string(spec) + "': " + key + " must be a number, got '" + value + "'");
    return v;
}

std::uint64_t to_seed(const std::string& value, std::string_view spec) {
    char* end = nullptr;
    errno = 0;
    const unsigned long long v = std::strtoull(value.c_str(), &end, 0);
    if (end == value.c_str() || *end != '\0' || errno != 0 || value[0] == '-')
        throw Error("generated scene '" + std::string(spec) + "': seed must be a non-negative integer, got '" + value + "'");
    return v;
}

int to_int(const std::string& key, const std::string& value, std::string_view spec) {
    const double v = to_number(key, value, spec);
    if (v != std::floor(v) || std::abs(v) > 1e9)
        throw Error("generated scene '" + std::string(spec) + "': " + key + " must be an integer, got '" + value + "'");
    return int(v);
}


// The toothpicks' options (and frame) from a spec's key=value options.
ToothpickSpec toothpick_options(std::map<std::string, std::string>& options, std::string_view spec) {
    auto take = [&](const char* key) -> const std::string* {
        auto it = options.find(key);
        return it == options.end() ? nullptr : &it->second;
    };
    ToothpickSpec t;
    if (auto v = take("seed")) t.options.seed = to_seed(*v, spec);
    if (auto v = take("count")) t.options.count = to_int("count", *v, spec);
    if (auto v = take("frame")) t.frame = to_int("frame", *v, spec);
    if (auto v = take("cube")) t.options.cube = to_number("cube", *v, spec);
    if (auto v = take("length")) t.options.length = to_number("length", *v, spec);
    if (auto v = take("thickness")) t.options.thickness = to_number("thickness", *v, spec);
    if (auto v = take("speed")) t.options.speed = to_number("speed", *v, spec);
    if (auto v = take("tumble")) t.options.tumble = to_number("tumble", *v, spec);
    if (auto v = take("density")) {
        if (*v != "uniform" && *v != "scale")
            throw Error("generated scene '" + std::string(spec) + "': density must be uniform or scale, got '" + *v + "'");
        t.options.uniform_density = *v == "uniform";
    }
    for (const char* k : {"seed", "count", "frame", "cube", "length", "thickness", "speed", "tumble", "density"}) options.erase(k);
    if (!options.empty())
        throw Error("generated scene '" + std::string(spec) + "': unknown option '" + options.begin()->first +
                    "' (toothpicks takes seed, count, density, frame, cube, length, thickness, speed, tumble)");
    return t;
}

}  // namespace

std::optional<ToothpickSpec> toothpick_spec(std::string_view spec) {
    if (spec.substr(0, 4) == "gen:") spec.remove_prefix(4);
    const std::size_t colon = spec.find(':');
    if (spec.substr(0, colon) != "toothpicks") return std::nullopt;
    auto options = parse_options(colon == std::string_view::npos ? std::string_view{} : spec.substr(colon + 1), spec);
    return toothpick_options(options, spec);
}

Scene generate_scene(std::string_view spec) {
    const std::size_t colon = spec.find(':');
    const std::string name(spec.substr(0, colon));
    auto options = parse_options(colon == std::string_view::npos ? std::string_view{} : spec.substr(colon + 1), spec);
    auto take = [&](const char* key) -> const std::string* {
        auto it = options.find(key);
        return it == options.end() ? nullptr : &it->second;
    };
    Scene scene;
    if (name == "city") {
        CityOptions o;
        if (auto v = take("seed")) o.seed = to_seed(*v, spec);
        if (auto v = take("blocks")) o.blocks = to_int("blocks", *v, spec);
        if (auto v = take("block")) o.block_size = to_number("block", *v, spec);
        if (auto v = take("street")) o.street_width = to_number("street", *v, spec);
        if (auto v = take("cars")) o.cars_per_block = to_int("cars", *v, spec);
        for (const char* k : {"seed", "blocks", "block", "street", "cars"}) options.erase(k);
        if (!options.empty())
            throw Error("generated scene '" + std::string(spec) + "': unknown option '" + options.begin()->first +
                        "' (city takes seed, blocks, block, street, cars)");
        scene = generate_city(o);
    } else if (name == "forest") {
        ForestOptions o;
        if (auto v = take("seed")) o.seed = to_seed(*v, spec);
        if (auto v = take("radius")) o.radius = to_number("radius", *v, spec);
        if (auto v = take("spacing")) o.tree_spacing = to_number("spacing", *v, spec);
        if (auto v = take("rocks")) o.rocks = to_int("rocks", *v, spec);
        for (const char* k : {"seed", "radius", "spacing", "rocks"}) options.erase(k);
        if (!options.empty())
            throw Error("generated scene '" + std::string(spec) + "': unknown option '" + options.begin()->first +
                        "' (forest takes seed, radius, spacing, rocks)");
        scene = generate_forest(o);
    } else if (name == "toothpicks") {
        const ToothpickSpec t = toothpick_options(options, spec);
        scene = generate_toothpicks(t.options, t.frame);
    } else {
        throw Error("unknown generated scene '" + name + "' (known: city, forest, toothpicks)");
    }
    scene.source = "gen:" + std::string(spec);
    return scene;
}

}  // namespace homcull
