// The image writers' module (lib/io/image_backend.hpp): OpenImageIO arrives with it, when the
// first image is written, and not with the program; without it, writing an image is an error
// that says where the module was looked for, and nothing else is affected.
#include "support.hpp"

#include <homcull/error.hpp>
#include <homcull/io/id_image.hpp>

#include <gtest/gtest.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <sstream>
#include <string>
#include <vector>
#include <sys/wait.h>

namespace homcull {
namespace {

std::string mapped_files() {
    std::ifstream maps("/proc/self/maps");
    std::stringstream text;
    text << maps.rdbuf();
    return text.str();
}

bool mapped(const std::string& maps, const std::string& file) { return maps.find(file) != std::string::npos; }

TEST(ImageModule, OpenImageIOComesWithTheModuleWhenAnImageIsWritten) {
    // Another test of this process may have written an image already: then both are there.
    const std::string before = mapped_files();
    if (!mapped(before, "homcull_oiio.so")) {
        EXPECT_FALSE(mapped(before, "libOpenImageIO")) << "OpenImageIO loaded at start";
    }
    const std::string path = test::temp_dir("image_module") + "/pixels.png";
    write_rgb_image(path, 2, 1, {255, 0, 0, 0, 0, 255});
    EXPECT_TRUE(std::filesystem::exists(path));
    const std::string after = mapped_files();
    EXPECT_TRUE(mapped(after, "homcull_oiio.so"));
    EXPECT_TRUE(mapped(after, "libOpenImageIO"));
}

TEST(ImageModule, AFailedLoadIsTriedAgainOnTheNextImage) {
    if (mapped(mapped_files(), "homcull_oiio.so"))
        GTEST_SKIP() << "the module is loaded already (another test of this process wrote an image; ctest runs each alone)";
    const std::string dir = test::temp_dir("image_module_retry");
    const char* before = std::getenv("HOMCULL_IMAGE_MODULE");
    const std::string kept = before ? before : "";
    ASSERT_EQ(setenv("HOMCULL_IMAGE_MODULE", (dir + "/no_such_module.so").c_str(), 1), 0);
    EXPECT_THROW(write_rgb_image(dir + "/first.png", 2, 1, {255, 0, 0, 0, 0, 255}), Error);
    EXPECT_FALSE(std::filesystem::exists(dir + "/first.png"));
    // The variable mended (here: unset, so that the usual places are searched), the next image
    // is written.
    if (before) ASSERT_EQ(setenv("HOMCULL_IMAGE_MODULE", kept.c_str(), 1), 0);
    else ASSERT_EQ(unsetenv("HOMCULL_IMAGE_MODULE"), 0);
    EXPECT_NO_THROW(write_rgb_image(dir + "/second.png", 2, 1, {255, 0, 0, 0, 0, 255}));
    EXPECT_TRUE(std::filesystem::exists(dir + "/second.png"));
}

int run(const std::string& command) {
    const int status = std::system(command.c_str());
    return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(ImageModule, WithoutItImagesFailAndSayWhereItWasLookedFor) {
    const std::string dir = test::temp_dir("image_module_missing");
    const std::string program = std::string("HOMCULL_IMAGE_MODULE=") + dir + "/no_such_module.so " + HOMCULL_CLI_PATH;
    const std::string camera = " --scene gen:city:seed=2,blocks=3 --eye -1,1.7,-30 --target 20,3,10 --resolution 96x54";
    // A command that writes no image runs as always.
    EXPECT_EQ(run(program + " cull" + camera + " >" + dir + "/cull.out 2>&1"), 0);
    // One that does is refused, naming the variable and the file.
    EXPECT_EQ(run(program + " dump" + camera + " --out " + dir + "/dump >" + dir + "/dump.out 2>&1"), 1);
    std::ifstream out(dir + "/dump.out");
    const std::string text((std::istreambuf_iterator<char>(out)), std::istreambuf_iterator<char>());
    EXPECT_NE(text.find("HOMCULL_IMAGE_MODULE"), std::string::npos) << text;
    EXPECT_NE(text.find(dir + "/no_such_module.so"), std::string::npos) << text;
    EXPECT_NE(text.find("homcull_oiio.so"), std::string::npos) << text;
}

}  // namespace
}  // namespace homcull
