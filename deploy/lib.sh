# shellcheck shell=bash
# Shared by deploy/quickstart.sh and deploy/lab-demo.sh (sourced, not run).

# Makes $build and $run absolute (relative ones are taken from the current directory) and names
# the programs built there: $brdfd, $sim (brdf-sim), $ctl (brdfctl).
# shellcheck disable=SC2034  # used by the scripts that source this file
resolve_build_and_run() {
  case "$build" in /*) ;; *) build="$PWD/$build" ;; esac
  case "$run" in /*) ;; *) run="$PWD/$run" ;; esac
  brdfd="$build/daemon/brdfd"
  sim="$build/tools/brdf-sim/brdf-sim"
  ctl="$build/tools/brdfctl/brdfctl"
}
