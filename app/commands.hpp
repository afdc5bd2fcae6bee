#pragma once

#include "exit_codes.hpp"

#include <CLI/CLI.hpp>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>

namespace skinmesh::app {

struct GlobalOptions {
  bool json = false;   // machine-readable output on stdout
  bool quiet = false;  // no progress or warnings on the terminal
  std::string command_line;  // as typed, for the reports
};

// "0.1.0" (the CMake project's version), with " (commit abc1234)" when built
// from a git checkout.
const char* version_text();


// CLI11's range checks let NaN through (every comparison with it is false)
// and accept infinities: every numeric option is checked by this first.
inline const CLI::Validator& finite_number() {
  static const CLI::Validator check(
      [](std::string& text) -> std::string {
        char* end = nullptr;
        const double value = std::strtod(text.c_str(), &end);
        if (end == text.c_str() || *end != '\0' || !std::isfinite(value)) return "must be a finite number, not " + text;
        return "";
      },
      "FINITE");
  return check;
}

// A number above 0, or at least 0: CLI11's PositiveNumber and
// NonNegativeNumber state their range with the largest double written out.
inline const CLI::Validator& positive_number() {
  static const CLI::Validator check(
      [](std::string& text) -> std::string {
        return std::strtod(text.c_str(), nullptr) > 0 ? "" : "must be greater than 0, not " + text;
      },
      "POSITIVE");
  return check;
}
inline const CLI::Validator& non_negative_number() {
  static const CLI::Validator check(
      [](std::string& text) -> std::string {
        return std::strtod(text.c_str(), nullptr) >= 0 ? "" : "must be 0 or more, not " + text;
      },
      "NON-NEGATIVE");
  return check;
}

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
void add_render_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_view_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_morph_command(CLI::App& app, const GlobalOptions& global, int& exit_code);
void add_trajectory_command(CLI::App& app, const GlobalOptions& global, int& exit_code);

}  // namespace skinmesh::app
