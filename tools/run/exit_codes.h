// SPDX-License-Identifier: MIT
// sph-run's exit codes (docs/cli.md lists them for users).
#ifndef SPH_TOOLS_EXIT_CODES_H
#define SPH_TOOLS_EXIT_CODES_H

namespace sph_tools {

enum ExitCode {
  kExitOk = 0,
  kExitRuntime = 1,       // the simulation or writing its output failed
  kExitUsage = 2,         // bad command line
  kExitScene = 3,         // the scene file cannot be read or is invalid
  kExitBackend = 4,       // the backend asked for is not available (no CUDA build or no GPU)
  kExitUnavailable = 5,   // an output this build lacks (vdb, --surface without OpenVDB)
  kExitInterrupted = 128  // + the signal number (130 for SIGINT, 143 for SIGTERM)
};

}  // namespace sph_tools

#endif
