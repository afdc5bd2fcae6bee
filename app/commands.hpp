#pragma once

#include <CLI/CLI.hpp>

namespace skinmesh::app {

struct GlobalOptions {
  bool json = false;   // machine-readable output on stdout
  bool quiet = false;  // no progress or warnings on the terminal
};

// Each adds its subcommand to `app`; the callback runs it and sets `exit_code`.
void add_info_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_quality_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_mesh_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_volume_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_interpolate_command(CLI::App& app, const GlobalOptions& global, int& exit_code);

}  // namespace skinmesh::app
