#pragma once
// Camera path files (DESIGN.md):
//   {"frames":[{"eye":[x,y,z],"target":[x,y,z],"up":[0,1,0],"fov_y":60,"near":0.1,"far":10000}, ...]}
// up, fov_y, near and far may be left out (the defaults above).
#include <homcull/camera.hpp>

#include <string>
#include <vector>

namespace homcull {

// Throws homcull::Error naming the file (and the frame) when it is missing, is not JSON, or
// holds an invalid camera.
CameraPath read_camera_path(const std::string& path);
CameraPath parse_camera_path(const std::string& json_text, const std::string& source);
std::string camera_path_to_json(const CameraPath& path);
void write_camera_path(const CameraPath& path, const std::string& file);

}  // namespace homcull
