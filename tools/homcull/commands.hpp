#pragma once
// Each subcommand of the homcull program registers itself on the top-level app.
#include <CLI/CLI.hpp>

namespace homcull::cli {

void register_info(CLI::App& app);
void register_truth(CLI::App& app);
void register_export(CLI::App& app);
void register_path(CLI::App& app);
void register_bench(CLI::App& app);
void register_accuracy(CLI::App& app);
void register_cull(CLI::App& app);
void register_walk(CLI::App& app);
void register_bake(CLI::App& app);
void register_dump(CLI::App& app);
void register_sort(CLI::App& app);

}  // namespace homcull::cli
