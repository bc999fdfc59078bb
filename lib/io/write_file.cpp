#include <homcull/io/write_file.hpp>

#include <homcull/error.hpp>

#include <cerrno>
#include <cstdio>
#include <cstring>
#include <filesystem>
#include <memory>

namespace homcull {
namespace {

[[noreturn]] void fail(const std::string& path, std::string_view what, const std::string& reason) {
    throw Error(path + ": cannot write " + std::string(what) + ": " + reason);
}

}  // namespace

void write_file(const std::string& path, std::string_view bytes, std::string_view what) {
    namespace fs = std::filesystem;
    std::error_code ec;
    if (path.empty()) fail(path, what, "no file name given");
    if (fs::is_directory(path, ec)) fail(path, what, "it is a folder");
    const fs::path parent = fs::path(path).parent_path();
    if (!parent.empty() && !fs::is_directory(parent, ec)) fail(path, what, "the folder " + parent.string() + " does not exist");
    std::FILE* raw = std::fopen(path.c_str(), "wb");
    if (!raw) fail(path, what, std::strerror(errno));
    std::unique_ptr<std::FILE, int (*)(std::FILE*)> file(raw, std::fclose);
    errno = 0;
    if (!bytes.empty() && std::fwrite(bytes.data(), 1, bytes.size(), file.get()) != bytes.size())
        fail(path, what, errno ? std::strerror(errno) : "short write");
    // The last buffered bytes reach the file only here: a full disk shows at the flush or close.
    if (std::fflush(file.get()) != 0) fail(path, what, std::strerror(errno));
    if (std::fclose(file.release()) != 0) fail(path, what, std::strerror(errno));
}

}  // namespace homcull
