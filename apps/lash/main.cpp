// lash — online deadzone/backlash identification, simulation and CAN HIL emulation.
#include <CLI/CLI.hpp>

#include "cli_common.hpp"

int main(int argc, char** argv) {
  using namespace lash::cli;
  // The one catch-all: building the app, parsing and running a subcommand all run inside it.
  return guarded([&]() -> int {
    CLI::App app{"lash: identify deadzones and backlash online, simulate such plants, emulate ECUs over CAN"};
    app.require_subcommand(1);
    app.set_version_flag("--version", "lash 0.1.0");
    std::vector<Command> commands{
        add_simulate(app),
        add_excite(app),
        add_demo(app),
        add_closed_loop(app),
        add_tune(app),
        add_identify_steps(app),
        add_estimate(app),
        add_sweep(app),
        add_can(app),
        add_hil(app),
        add_xcp(app),
        add_monitor(app),
        add_console(app),
    };
    try {
      app.parse(argc, argv);
    } catch (const CLI::ParseError& e) {
      const int rc = app.exit(e);
      return rc == 0 ? 0 : kExitBadInput;
    }
    for (auto& c : commands)
      if (c.app->parsed()) return c.run();
    return kExitBadInput;
  });
}
