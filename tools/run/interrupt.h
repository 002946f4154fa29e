// SPDX-License-Identifier: MIT
// Ctrl-C and SIGTERM: the first asks the run to stop after the frame in progress is complete
// (or discarded); the second ends the process at once.
#ifndef SPH_TOOLS_INTERRUPT_H
#define SPH_TOOLS_INTERRUPT_H

namespace sph_tools {

void install_interrupt_handlers();
// The signal that asked to stop, or 0.
int interrupt_signal();

}  // namespace sph_tools

#endif
