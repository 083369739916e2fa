// lamina: the command-line tool. Offline commands work on a model file directly; ports and
// stream talk to the machine through drivers/.
#include "commands.hpp"
#include "malloc_tuning.hpp"

int main(int argc, char** argv) {
  lamina::cli::restart_with_malloc_tuning(argc, argv);
  CLI::App app{"lamina — laminated parts for 5-axis abrasive waterjets"};
  app.require_subcommand(1);
  int exit_code = 0;
  lamina::cli::add_check_command(app, exit_code);
  lamina::cli::add_slice_command(app, exit_code);
  lamina::cli::add_plan_command(app, exit_code);
  lamina::cli::add_ports_command(app, exit_code);
  lamina::cli::add_stream_command(app, exit_code);
  lamina::cli::add_client_commands(app, exit_code);
  lamina::cli::add_calibrate_command(app, exit_code);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // CLI11 prints the message (and --help); every usage error exits 2, as in most Unix tools.
    const int code = app.exit(e);
    return code == 0 ? 0 : 2;
  }
  return exit_code;
}
