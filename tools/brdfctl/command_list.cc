// brdfctl's subcommands, each family registered by its own file, in the order `brdfctl --help`
// lists them.
#include "tools/brdfctl/command.h"
#include "tools/brdfctl/commands/appearance.h"
#include "tools/brdfctl/commands/control.h"
#include "tools/brdfctl/commands/export.h"
#include "tools/brdfctl/commands/interpolate.h"
#include "tools/brdfctl/commands/readings.h"
#include "tools/brdfctl/commands/rounds.h"
#include "tools/brdfctl/commands/sim_mount.h"
#include "tools/brdfctl/commands/watch.h"

namespace brdf::ctl {

CommandRegistry BrdfctlCommands() {
  CommandRegistry registry;
  RegisterPlanCommands(registry);      // validate, submit
  RegisterOperatorCommands(registry);  // start, pause, resume, abort, answer
  RegisterViewCommands(registry);      // get, events, list, rig
  RegisterWatchCommand(registry);
  RegisterRoundsCommand(registry);
  RegisterReadingsCommand(registry);
  RegisterInterpolateCommand(registry);
  RegisterAppearanceCommand(registry);
  RegisterExportCommand(registry);
  RegisterSimMountCommand(registry);
  return registry;
}

}  // namespace brdf::ctl
