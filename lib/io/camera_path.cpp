#include <homcull/error.hpp>
#include <homcull/io/camera_path.hpp>
#include <homcull/io/write_file.hpp>

#include <nlohmann/json.hpp>

#include <fstream>
#include <sstream>

namespace homcull {
namespace {

glm::dvec3 read_vec3(const nlohmann::json& frame, const char* key, const glm::dvec3& fallback,
                     const std::string& where) {
    if (!frame.contains(key)) {
        if (std::string(key) == "eye" || std::string(key) == "target") throw Error(where + ": missing \"" + key + "\"");
        return fallback;
    }
    const auto& v = frame[key];
    if (!v.is_array() || v.size() != 3 || !v[0].is_number() || !v[1].is_number() || !v[2].is_number())
        throw Error(where + ": \"" + key + "\" must be an array of three numbers");
    return {v[0].get<double>(), v[1].get<double>(), v[2].get<double>()};
}

double read_number(const nlohmann::json& frame, const char* key, double fallback, const std::string& where) {
    if (!frame.contains(key)) return fallback;
    if (!frame[key].is_number()) throw Error(where + ": \"" + key + "\" must be a number");
    return frame[key].get<double>();
}

}  // namespace

CameraPath parse_camera_path(const std::string& text, const std::string& source) {
    nlohmann::json j = nlohmann::json::parse(text, nullptr, false);
    if (j.is_discarded()) throw Error(source + ": not valid JSON");
    if (!j.is_object() || !j.contains("frames") || !j["frames"].is_array())
        throw Error(source + ": expected {\"frames\": [...]}");
    CameraPath path;
    const Camera defaults;
    for (std::size_t k = 0; k < j["frames"].size(); ++k) {
        const auto& f = j["frames"][k];
        const std::string where = source + ": frame " + std::to_string(k);
        if (!f.is_object()) throw Error(where + ": expected an object");
        Camera c;
        c.eye = read_vec3(f, "eye", defaults.eye, where);
        c.target = read_vec3(f, "target", defaults.target, where);
        c.up = read_vec3(f, "up", defaults.up, where);
        c.fov_y_degrees = read_number(f, "fov_y", defaults.fov_y_degrees, where);
        c.near_plane = read_number(f, "near", defaults.near_plane, where);
        c.far_plane = read_number(f, "far", defaults.far_plane, where);
        try {
            validate_camera(c);
        } catch (const Error& e) {
            throw Error(where + ": " + e.what());
        }
        path.frames.push_back(c);
    }
    if (path.frames.empty()) throw Error(source + ": the path has no frames");
    return path;
}

CameraPath read_camera_path(const std::string& file) {
    std::ifstream in(file, std::ios::binary);
    if (!in) throw Error(file + ": cannot open the camera path file");
    std::stringstream text;
    text << in.rdbuf();
    return parse_camera_path(text.str(), file);
}

std::string camera_path_to_json(const CameraPath& path) {
    nlohmann::json frames = nlohmann::json::array();
    for (const Camera& c : path.frames)
        frames.push_back({{"eye", {c.eye.x, c.eye.y, c.eye.z}},
                          {"target", {c.target.x, c.target.y, c.target.z}},
                          {"up", {c.up.x, c.up.y, c.up.z}},
                          {"fov_y", c.fov_y_degrees},
                          {"near", c.near_plane},
                          {"far", c.far_plane}});
    // One frame per line: readable, and diffs of path files stay small.
    std::string out = "{\"frames\":[\n";
    for (std::size_t k = 0; k < frames.size(); ++k) out += frames[k].dump() + (k + 1 < frames.size() ? ",\n" : "\n");
    return out + "]}\n";
}

void write_camera_path(const CameraPath& path, const std::string& file) {
    write_file(file, camera_path_to_json(path), "the camera path");
}

}  // namespace homcull
