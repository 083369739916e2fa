#pragma once
#include <CLI/CLI.hpp>

namespace lamina::cli {

// Each adds its subcommand; the callback stores the process exit code in `exit_code`.
void add_check_command(CLI::App& app, int& exit_code);
void add_slice_command(CLI::App& app, int& exit_code);
void add_plan_command(CLI::App& app, int& exit_code);
void add_ports_command(CLI::App& app, int& exit_code);
void add_stream_command(CLI::App& app, int& exit_code);
void add_client_commands(CLI::App& app, int& exit_code);  // laminad: submit, jobs, status…
void add_calibrate_command(CLI::App& app, int& exit_code);  // the jet's kerf from test cuts

}  // namespace lamina::cli
