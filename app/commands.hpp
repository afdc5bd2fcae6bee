#pragma once

#include "exit_codes.hpp"

#include <CLI/CLI.hpp>

#include <memory>

namespace skinmesh::app {

struct GlobalOptions {
  bool json = false;   // machine-readable output on stdout
  bool quiet = false;  // no progress or warnings on the terminal
};

// Adds subcommand `name`: its options are declared on an Options struct by
// add_options, and the callback runs `run` with them and sets `exit_code`.
template <class Options>
void add_command(CLI::App& app, const char* name, const char* description, const GlobalOptions& global,
                 int& exit_code, void (*add_options)(CLI::App&, Options&),
                 ExitCode (*run)(const Options&, const GlobalOptions&)) {
  auto options = std::make_shared<Options>();
  CLI::App* cmd = app.add_subcommand(name, description);
  add_options(*cmd, *options);
  cmd->callback([options, run, &global, &exit_code]() { exit_code = code(run(*options, global)); });
}

// Each adds its subcommand to `app`; the callback runs it and sets `exit_code`.
void add_info_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_quality_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_mesh_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_volume_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_interpolate_command(CLI::App& app, const GlobalOptions& global, int& exit_code);

}  // namespace skinmesh::app
