#pragma once
// The TrueType font the image writers (dumps, plots) draw their text with.
#include <string>

namespace homcull::detail {

// Found once: OIIO's default (DroidSans) ships with OIIO's own font folder, which Debian's
// package does not install, so DejaVu Sans (fonts-dejavu-core) is tried first. Empty name and
// a reason when neither renders.
struct LegendFont {
    bool found = false;
    std::string name, reason;
};

const LegendFont& legend_font();

}  // namespace homcull::detail
