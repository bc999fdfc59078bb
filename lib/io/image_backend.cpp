#include "io/image_backend.hpp"

#include <homcull/error.hpp>

#include <dlfcn.h>

#include <atomic>
#include <cstdlib>
#include <filesystem>
#include <mutex>
#include <system_error>

// Compiled in by lib/CMakeLists.txt: the module in this build tree, and the library folder
// relative to the install prefix (lib, lib64, lib/x86_64-linux-gnu, ...).
#ifndef HOMCULL_IMAGE_MODULE_BUILD_PATH
#error "HOMCULL_IMAGE_MODULE_BUILD_PATH: the build tree's homcull_oiio.so"
#endif
#ifndef HOMCULL_INSTALL_LIBDIR
#error "HOMCULL_INSTALL_LIBDIR: the library folder under the install prefix"
#endif

namespace homcull::detail {
namespace {

struct Loaded {
    const ImageBackend* backend = nullptr;
    std::string tried;  // each place tried and why it failed, when none worked
};

// The module at `where` (a path, or a bare file name for the library search path), or null and
// why in `tried`. A module that loads but is not this build's is closed again.
const ImageBackend* try_load(const std::string& where, std::string& tried) {
    // RTLD_LOCAL: OpenImageIO's symbols stay out of the program's namespace.
    void* handle = dlopen(where.c_str(), RTLD_NOW | RTLD_LOCAL);
    if (!handle) {
        const char* error = dlerror();
        std::string why = error ? error : "cannot be loaded";
        if (why.rfind(where + ": ", 0) == 0) why.erase(0, where.size() + 2);  // dlerror names the file too
        tried += "\n  " + where + ": " + why;
        return nullptr;
    }
    using Entry = const ImageBackend* (*)();
    const auto entry = reinterpret_cast<Entry>(dlsym(handle, kImageBackendEntry));
    const ImageBackend* backend = entry ? entry() : nullptr;
    if (!backend || backend->version != kImageBackendVersion) {
        tried += "\n  " + where + ": " +
                 (backend ? "from another build of homcull (backend version " + std::to_string(backend->version) + ", this one " +
                                std::to_string(kImageBackendVersion) + ")"
                          : std::string("has no ") + kImageBackendEntry);
        dlclose(handle);
        return nullptr;
    }
    return backend;  // kept loaded for the life of the program
}

std::string installed_next_to_program() {
    std::error_code ec;
    const std::filesystem::path program = std::filesystem::read_symlink("/proc/self/exe", ec);
    if (ec) return "";
    return (program.parent_path().parent_path() / HOMCULL_INSTALL_LIBDIR / "homcull" / kImageModuleName).string();
}

Loaded load() {
    Loaded r;
    if (const char* chosen = std::getenv(kImageModuleVariable); chosen && *chosen) {
        r.backend = try_load(chosen, r.tried);
        if (!r.backend) r.tried = std::string(" from ") + kImageModuleVariable + ":" + r.tried;
        return r;
    }
    std::error_code ec;
    for (const std::string& where : {installed_next_to_program(), std::string(kImageModuleName), std::string(HOMCULL_IMAGE_MODULE_BUILD_PATH)}) {
        if (where.empty()) continue;
        // A full path that does not exist says so more plainly than dlopen.
        if (where.find('/') != std::string::npos && !std::filesystem::exists(where, ec)) {
            r.tried += "\n  " + where + ": no such file";
            continue;
        }
        if ((r.backend = try_load(where, r.tried))) return r;
    }
    r.tried = ", tried:" + r.tried + "\n(it is built with homcull::io, and installed to <libdir>/homcull; " + kImageModuleVariable +
              " may name it)";
    return r;
}

}  // namespace

const ImageBackend& image_backend() {
    // A module once loaded stays loaded and is returned at once. A failure is not kept: a
    // program that then sets $HOMCULL_IMAGE_MODULE or installs the module can write images
    // without restarting (each failed call looks again, one thread at a time).
    static std::atomic<const ImageBackend*> loaded{nullptr};
    if (const ImageBackend* backend = loaded.load(std::memory_order_acquire)) return *backend;
    static std::mutex loading;
    const std::lock_guard<std::mutex> lock(loading);
    if (const ImageBackend* backend = loaded.load(std::memory_order_acquire)) return *backend;
    const Loaded attempt = load();
    if (!attempt.backend)
        throw Error(std::string("homcull's image writer (") + kImageModuleName + ", OpenImageIO) could not be loaded" + attempt.tried);
    loaded.store(attempt.backend, std::memory_order_release);
    return *attempt.backend;
}

void write_rgb_pixels(const std::string& path, int width, int height, const std::uint8_t* rgb, const char* format) {
    ImagePart image;
    image.width = width;
    image.height = height;
    image.channels = 3;
    image.pixels = rgb;
    const std::string why = image_backend().write(path, &image, 1, format);
    if (!why.empty()) throw Error(path + ": " + why);
}

}  // namespace homcull::detail
