// Each subcommand lives in its own file: it fills its module's Options from the command line and
// calls the module. main.cpp only registers them.
#pragma once

#include <CLI/CLI.hpp>

namespace lucent::cli {

void register_profile_command(CLI::App& app);
void register_simulate_command(CLI::App& app);
void register_acquire_command(CLI::App& app);
void register_fit_command(CLI::App& app);
void register_bench_command(CLI::App& app);
void register_render_command(CLI::App& app);
void register_view_command(CLI::App& app);
void register_tabulate_command(CLI::App& app);
void register_compare_command(CLI::App& app);
void register_tonemap_command(CLI::App& app);
void register_material_commands(CLI::App& app);
void register_merge_command(CLI::App& app);

}  // namespace lucent::cli
