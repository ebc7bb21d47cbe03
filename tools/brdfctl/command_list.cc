// brdfctl's subcommands, each family registered by its own file, in the order `brdfctl --help`
// lists them.
#include "tools/brdfctl/appearance_command.h"
#include "tools/brdfctl/command.h"
#include "tools/brdfctl/control_commands.h"
#include "tools/brdfctl/export_command.h"
#include "tools/brdfctl/interpolate_command.h"
#include "tools/brdfctl/readings_command.h"
#include "tools/brdfctl/sim_mount.h"
#include "tools/brdfctl/watch_command.h"

namespace brdf::ctl {

CommandRegistry BrdfctlCommands() {
  CommandRegistry registry;
  RegisterPlanCommands(registry);      // validate, submit
  RegisterOperatorCommands(registry);  // start, pause, resume, abort, answer
  RegisterViewCommands(registry);      // get, events, list, rig
  RegisterWatchCommand(registry);
  RegisterReadingsCommand(registry);
  RegisterInterpolateCommand(registry);
  RegisterAppearanceCommand(registry);
  RegisterExportCommand(registry);
  RegisterSimMountCommand(registry);
  return registry;
}

}  // namespace brdf::ctl
