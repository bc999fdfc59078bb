#pragma once
// Writing a whole output file, with every failure reported: the path is a folder, its folder
// does not exist, the file cannot be opened, or a write or the final flush fails (a full disk,
// /dev/full). The one way the tools and the io library write files, so that no command says
// "wrote X" when nothing was written.
#include <string>
#include <string_view>

namespace homcull {

// Writes `bytes` to `path` (replacing it). Throws homcull::Error, naming the path, `what` (for
// example "the camera path") and the system's reason, on any failure. A missing parent folder
// is an error, not created.
void write_file(const std::string& path, std::string_view bytes, std::string_view what);

}  // namespace homcull
