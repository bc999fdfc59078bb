#pragma once
// The walkthrough report of `homcull walk --dump DIR`: Zhang's culling graph and the time per
// frame as PNG plots, one HTML page showing them with the summary, and the first frame's dump.
#include <homcull/truth/walkthrough.hpp>

#include <nlohmann/json.hpp>

#include <string>
#include <vector>

namespace homcull::cli {

// Writes DIR/culling_graph.png, DIR/objects_graph.png, DIR/frame_ms.png and DIR/report.html.
// `summary` is walk's summary JSON, `settings` the walk's settings as name/value lines, and
// `frame_dump` the folder (relative to DIR) holding a frame's dump, or "" for none. Returns
// the files written.
std::vector<std::string> write_walk_report(const std::string& dir, const std::string& title,
                                           const std::vector<std::pair<std::string, std::string>>& settings,
                                           const std::vector<WalkFrame>& frames, const nlohmann::json& summary,
                                           const std::string& frame_dump);

}  // namespace homcull::cli
