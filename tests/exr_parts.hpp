#pragma once
// Reading a multi-part EXR dump back, for the dump and golden-image tests.
#include <string>
#include <vector>

namespace homcull::test {

struct ExrPart {
    std::string name;  // the part name (EXR "name", OIIO's oiio:subimagename)
    int width = 0, height = 0, channels = 0;
    bool stored_as_float = false;  // the file's channels are 32-bit float
    std::vector<float> values;     // read as float, row-major, channels interleaved
};

// Every part of the file, in file order. Throws homcull::Error naming the file.
std::vector<ExrPart> read_exr_parts(const std::string& path);

}  // namespace homcull::test
