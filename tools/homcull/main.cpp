// homcull: the command-line program. Results go to stdout (text, or JSON with --json);
// progress and diagnostics to stderr. Exit codes: 0 success, 1 bad input (a message says
// what and where), 2 internal error, CLI11's codes for usage errors.
#include "commands.hpp"

#include <homcull/error.hpp>

#include <cstdio>
#include <exception>

int main(int argc, char** argv) {
    CLI::App app{"homcull: CPU occlusion culling with coverage masks and hierarchical occlusion maps"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "homcull 0.1.0");
    homcull::cli::register_info(app);
    homcull::cli::register_truth(app);
    homcull::cli::register_export(app);
    homcull::cli::register_path(app);
    homcull::cli::register_bench(app);
    homcull::cli::register_accuracy(app);
    homcull::cli::register_cull(app);
    homcull::cli::register_walk(app);
    homcull::cli::register_bake(app);
    homcull::cli::register_dump(app);
    homcull::cli::register_sort(app);
    try {
        app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
        return app.exit(e);
    } catch (const homcull::Error& e) {
        std::fprintf(stderr, "homcull: error: %s\n", e.what());
        return 1;
    } catch (const std::exception& e) {
        std::fprintf(stderr, "homcull: internal error: %s\n", e.what());
        return 2;
    }
    return 0;
}
