// lamina: the command-line tool. Offline commands work on a model file directly.
#include "commands.hpp"

int main(int argc, char** argv) {
  CLI::App app{"lamina — laminated parts for 5-axis abrasive waterjets"};
  app.require_subcommand(1);
  int exit_code = 0;
  lamina::cli::add_check_command(app, exit_code);
  lamina::cli::add_slice_command(app, exit_code);
  CLI11_PARSE(app, argc, argv);
  return exit_code;
}
