#include <homcull/error.hpp>
#include <homcull/io/write_file.hpp>
#include <homcull/io/visibility_grid_io.hpp>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <fstream>
#include <numeric>
#include <sstream>

namespace homcull {
namespace {

constexpr const char* kFormat = "homcull-visibility-grid";

nlohmann::json header_json(const VisibilityGridHeader& h) {
    return {{"format", kFormat},
            {"version", 1},
            {"scene", h.scene},
            {"scene_objects", h.scene_objects},
            {"scene_triangles", h.scene_triangles},
            {"occluders", h.occluders},
            {"layout", grid_layout_name(h.layout)},
            {"spacing", h.spacing},
            {"origin", {h.origin_x, h.origin_y, h.origin_z}},
            {"columns", {h.columns_x, h.columns_z}},
            {"eye_height", h.eye_height},
            {"rays", h.rays},
            {"keep", h.keep}};
}

// A field of the file, of the expected JSON type, or an error naming both.
const nlohmann::json& field(const nlohmann::json& j, const char* key, nlohmann::json::value_t type, const std::string& where) {
    const auto it = j.find(key);
    const bool number = type == nlohmann::json::value_t::number_float;
    if (it == j.end() || (number ? !it->is_number() : it->type() != type))
        throw Error(where + ": missing or malformed \"" + key + "\"");
    return *it;
}

using T = nlohmann::json::value_t;

// An unsigned JSON number that fits in 32 bits (nlohmann's get<uint32_t> would wrap).
std::uint32_t u32(const nlohmann::json& value, const char* what, const std::string& where) {
    if (!value.is_number_unsigned() || value.get<std::uint64_t>() > 0xFFFFFFFFull)
        throw Error(where + ": " + what + " must be a count below 2^32");
    return std::uint32_t(value.get<std::uint64_t>());
}

VisibilityGridHeader parse_header(const nlohmann::json& j, const std::string& where) {
    if (!j.is_object() || !j.contains("format") || j["format"] != kFormat) throw Error(where + ": not a homcull visibility grid");
    if (!j.contains("version") || j["version"] != 1) throw Error(where + ": unsupported visibility grid version");
    VisibilityGridHeader h;
    h.scene = field(j, "scene", T::string, where).get<std::string>();
    h.scene_objects = field(j, "scene_objects", T::number_unsigned, where).get<std::size_t>();
    h.scene_triangles = field(j, "scene_triangles", T::number_unsigned, where).get<std::size_t>();
    h.occluders = field(j, "occluders", T::string, where).get<std::string>();
    const std::string layout = field(j, "layout", T::string, where).get<std::string>();
    if (layout != "floors" && layout != "volume") throw Error(where + ": unknown layout \"" + layout + "\"");
    h.layout = layout == "volume" ? GridLayout::volume : GridLayout::floors;
    h.spacing = field(j, "spacing", T::number_float, where).get<double>();
    const auto& origin = field(j, "origin", T::array, where);
    const auto& columns = field(j, "columns", T::array, where);
    if (origin.size() != 3 || !origin[0].is_number() || !origin[1].is_number() || !origin[2].is_number())
        throw Error(where + ": \"origin\" must be three numbers");
    if (columns.size() != 2) throw Error(where + ": \"columns\" must be two counts");
    h.origin_x = origin[0].get<double>();
    h.origin_y = origin[1].get<double>();
    h.origin_z = origin[2].get<double>();
    h.columns_x = u32(columns[0], "a column count", where);
    h.columns_z = u32(columns[1], "a column count", where);
    if (std::uint64_t(h.columns_x) * h.columns_z > (1u << 26)) throw Error(where + ": too many columns");
    h.eye_height = field(j, "eye_height", T::number_float, where).get<double>();
    h.rays = u32(field(j, "rays", T::number_unsigned, where), "\"rays\"", where);
    h.keep = u32(field(j, "keep", T::number_unsigned, where), "\"keep\"", where);
    return h;
}

bool same_header(const VisibilityGridHeader& a, const VisibilityGridHeader& b) {
    return header_json(a) == header_json(b);
}

}  // namespace

void write_visibility_grid(const VisibilityGrid& grid, const GridShard& shard, const std::string& file) {
    nlohmann::json j = header_json(grid.header);
    if (shard.count > 1) j["shard"] = {shard.index, shard.count};
    nlohmann::json points = nlohmann::json::array();
    for (std::size_t c = 0; c < grid.column_count(); ++c) {
        for (std::uint32_t p = grid.column_first[c]; p < grid.column_first[c + 1]; ++p) {
            const GridPoint& point = grid.points[p];
            nlohmann::json occluders = nlohmann::json::array();
            for (const auto& [id, score] : point.occluders) occluders.push_back({id, score});
            points.push_back({{"column", c},
                              {"position", {point.position.x, point.position.y, point.position.z}},
                              {"occluders", std::move(occluders)}});
        }
    }
    j["points"] = std::move(points);
    write_file(file, j.dump() + "\n", "the visibility grid");
}

VisibilityGridPart read_visibility_grid_part(const std::string& file) {
    std::ifstream in(file);
    if (!in) throw Error("cannot open the visibility grid " + file);
    std::stringstream text;
    text << in.rdbuf();
    const nlohmann::json j = nlohmann::json::parse(text.str(), nullptr, false);
    if (j.is_discarded()) throw Error(file + ": not valid JSON");
    VisibilityGridPart part;
    part.source = file;
    VisibilityGrid& grid = part.grid;
    grid.header = parse_header(j, file);
    if (j.contains("shard")) {
        const auto& s = j["shard"];
        if (!s.is_array() || s.size() != 2) throw Error(file + ": \"shard\" must be [index, count] with index < count");
        part.shard = {u32(s[0], "a shard index", file), u32(s[1], "a shard count", file)};
        if (part.shard.index >= part.shard.count) throw Error(file + ": \"shard\" must be [index, count] with index < count");
    }
    // Points grouped by column, in file order within a column.
    const auto& points = field(j, "points", T::array, file);
    std::vector<std::pair<std::size_t, std::size_t>> order;  // (column, file index)
    std::vector<GridPoint> read;
    for (std::size_t k = 0; k < points.size(); ++k) {
        const std::string where = file + ": point " + std::to_string(k);
        const auto& p = points[k];
        if (!p.is_object()) throw Error(where + ": expected an object");
        const std::size_t column = field(p, "column", T::number_unsigned, where).get<std::size_t>();
        if (column >= grid.column_count()) throw Error(where + ": column " + std::to_string(column) + " is outside the grid");
        if (!part.shard.holds(column)) throw Error(where + ": column " + std::to_string(column) + " does not belong to this shard");
        const auto& position = field(p, "position", T::array, where);
        if (position.size() != 3 || !position[0].is_number() || !position[1].is_number() || !position[2].is_number())
            throw Error(where + ": \"position\" must be three numbers");
        GridPoint point;
        point.position = {position[0].get<float>(), position[1].get<float>(), position[2].get<float>()};
        for (const auto& o : field(p, "occluders", T::array, where)) {
            if (!o.is_array() || o.size() != 2 || !o[0].is_number_unsigned() || !o[1].is_number_unsigned())
                throw Error(where + ": an occluder must be [object id, score]");
            point.occluders.emplace_back(u32(o[0], "an object id", where), u32(o[1], "a score", where));
        }
        order.emplace_back(column, k);
        read.push_back(std::move(point));
    }
    std::stable_sort(order.begin(), order.end(), [](const auto& a, const auto& b) { return a.first < b.first; });
    grid.column_first.assign(grid.column_count() + 1, 0);
    for (const auto& [column, k] : order) {
        ++grid.column_first[column + 1];
        grid.points.push_back(std::move(read[k]));
    }
    std::partial_sum(grid.column_first.begin(), grid.column_first.end(), grid.column_first.begin());
    grid.index(grid.header.scene_objects, file);
    return part;
}

VisibilityGrid merge_visibility_grid_parts(const std::vector<VisibilityGridPart>& parts) {
    if (parts.empty()) throw Error("merge: no visibility grid parts given");
    const std::uint32_t count = parts.front().shard.count;
    if (count != parts.size())
        throw Error("merge: " + parts.front().source + " is one of " + std::to_string(count) + " shards, but the files given number " +
                    std::to_string(parts.size()) +
                    (count > parts.size() ? ": shard files are missing" : ": some are given twice or come from another bake"));
    std::vector<const VisibilityGridPart*> by_index(count, nullptr);
    for (const VisibilityGridPart& part : parts) {
        if (part.shard.count != count)
            throw Error("merge: " + part.source + " is shard " + std::to_string(part.shard.index) + " of " +
                        std::to_string(part.shard.count) + ", " + parts.front().source + " one of " + std::to_string(count));
        if (!same_header(part.grid.header, parts.front().grid.header))
            throw Error("merge: " + part.source + " and " + parts.front().source + " come from different bakes (their headers differ)");
        if (by_index[part.shard.index])
            throw Error("merge: shard " + std::to_string(part.shard.index) + " is given twice (" + by_index[part.shard.index]->source +
                        ", " + part.source + ")");
        by_index[part.shard.index] = &part;
    }
    for (std::uint32_t i = 0; i < count; ++i)
        if (!by_index[i]) throw Error("merge: shard " + std::to_string(i) + " of " + std::to_string(count) + " is missing");
    VisibilityGrid grid;
    grid.header = parts.front().grid.header;
    grid.column_first.assign(1, 0);
    for (std::size_t c = 0; c < grid.column_count(); ++c) {
        const VisibilityGrid& from = by_index[c % count]->grid;
        grid.points.insert(grid.points.end(), from.points.begin() + from.column_first[c], from.points.begin() + from.column_first[c + 1]);
        grid.column_first.push_back(std::uint32_t(grid.points.size()));
    }
    grid.index(grid.header.scene_objects, "merge");
    return grid;
}

VisibilityGrid read_visibility_grid(const std::string& file, const Scene& scene) {
    VisibilityGridPart part = read_visibility_grid_part(file);
    if (part.shard.count != 1)
        throw Error(file + " is shard " + std::to_string(part.shard.index) + " of " + std::to_string(part.shard.count) +
                    " of a bake: merge the shards first (homcull bake --merge)");
    const VisibilityGridHeader& h = part.grid.header;
    if (h.scene_objects != scene.objects.size() || h.scene_triangles != scene.instanced_triangle_count())
        throw Error(file + " was baked for " + h.scene + " (" + std::to_string(h.scene_objects) + " objects, " +
                    std::to_string(h.scene_triangles) + " triangles), not for " + scene.source + " (" +
                    std::to_string(scene.objects.size()) + " objects, " + std::to_string(scene.instanced_triangle_count()) +
                    " triangles)");
    return std::move(part.grid);
}

}  // namespace homcull
