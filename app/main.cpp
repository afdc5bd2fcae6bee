// skinmesh: molecular skin surfaces, quality meshes and morphs.
#include "commands.hpp"
#include "exit_codes.hpp"
#include "interrupt.hpp"
#include "output_file.hpp"
#include "suggest.hpp"

#include "skinmesh/core/allocator.hpp"
#include "skinmesh/core/error.hpp"

#include <iostream>
#include <new>
#include <string>
#include <vector>

const char* skinmesh::app::version_text() {
#ifdef SKINMESH_COMMIT
  return SKINMESH_VERSION " (commit " SKINMESH_COMMIT ")";
#else
  return SKINMESH_VERSION;
#endif
}

namespace {

// One example a command, at the end of its --help.
void add_examples(CLI::App& app) {
  const std::pair<const char*, const char*> examples[] = {
      {"info", "skinmesh info data/1ubi.pdb"},
      {"mesh", "skinmesh mesh data/1ubi.pdb -o ubi.ply --report ubi.json"},
      {"quality", "skinmesh quality ubi.ply --molecule data/1ubi.pdb --svg ubi.svg"},
      {"volume", "skinmesh volume data/pept.pdb -o pept --domain both --box-margin 4"},
      {"interpolate", "skinmesh interpolate data/pept.pdb data/3al1.pdb --t 0.5 -o half.wpts"},
      {"morph", "skinmesh morph data/2k39_3models.pdb data/2k39_3models.pdb --target-model 3 -o morph/"},
      {"trajectory", "skinmesh trajectory data/2k39_3models.pdb -o ensemble/ --frames-per-step 5"},
      {"render", "skinmesh render data/1ubi.pdb -o ubi.png --colour patch"},
      {"view", "skinmesh view ubi.ply -o ubi.html"},
  };
  for (const auto& [name, example] : examples) app.get_subcommand(name)->footer(std::string("Example:\n  ") + example);
}

}  // namespace

int main(int argc, char** argv) {
  skinmesh::app::watch_interrupts();  // first: before any thread starts
  skinmesh::return_large_blocks_to_system();
  CLI::App app{"skinmesh: quality meshes of molecular skin surfaces"};
  app.require_subcommand(1);
  app.fallthrough();  // --json and --quiet may follow the subcommand
  skinmesh::app::GlobalOptions global;
  for (int i = 0; i < argc; ++i) global.command_line += (i ? " " : "") + std::string(argv[i]);
  app.set_version_flag("--version", std::string("skinmesh ") + skinmesh::app::version_text());
  app.option_defaults()->always_capture_default();  // every option's help shows its default
  app.add_flag("--json", global.json, "machine-readable JSON on stdout (before or after the command)");
  app.add_flag("--quiet,-q", global.quiet,
               "no progress, warnings or summary on the terminal (before or after the command); the outputs, "
               "--json and the exit code still say how it went");
  int exit_code = code(skinmesh::app::ExitCode::ok);
  skinmesh::app::add_info_command(app, global, exit_code);
  skinmesh::app::add_mesh_command(app, global, exit_code);
  skinmesh::app::add_quality_command(app, global, exit_code);
  skinmesh::app::add_volume_command(app, global, exit_code);
  skinmesh::app::add_interpolate_command(app, global, exit_code);
  skinmesh::app::add_morph_command(app, global, exit_code);
  skinmesh::app::add_trajectory_command(app, global, exit_code);
  skinmesh::app::add_render_command(app, global, exit_code);
  skinmesh::app::add_view_command(app, global, exit_code);
  add_examples(app);
  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    // --help and --version end the parse with code 0; every usage error is
    // a bad option (exit 2), with the nearest name when one was mistyped.
    if (app.exit(e) == 0) return 0;
    const std::string hint = skinmesh::app::suggestion(app, std::vector<std::string>(argv + 1, argv + argc));
    if (!hint.empty()) std::cerr << "skinmesh: " << hint << "\n";
    return code(skinmesh::app::ExitCode::bad_input);
  } catch (const skinmesh::app::UnusableOutput& e) {
    std::cerr << "skinmesh: error: " << e.what() << "\n";
    return code(skinmesh::app::ExitCode::bad_input);
  } catch (const skinmesh::InputError& e) {
    std::cerr << "skinmesh: error: " << e.what() << "\n";
    return code(skinmesh::app::ExitCode::bad_input);
  } catch (const skinmesh::ContractError& e) {
    std::cerr << "skinmesh: error: " << e.what() << "\n";
    return code(skinmesh::app::ExitCode::bad_input);
  } catch (const std::bad_alloc&) {
    // The estimates refuse most jobs too large at once; this is one that
    // got past them (or a limit they cannot see).
    std::cerr << "skinmesh: error: out of memory running `" << global.command_line
              << "`: the job needs more than this process may use (ulimit -v, the cgroup's limit or the machine's "
                 "memory); nothing written\n";
    return code(skinmesh::app::ExitCode::not_met);
  } catch (const std::exception& e) {
    std::cerr << "skinmesh: error: " << e.what() << "\n";
    return code(skinmesh::app::ExitCode::failure);
  }
  return exit_code;
}
