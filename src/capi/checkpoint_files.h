// SPDX-License-Identifier: MIT
// Checkpoint files: written atomically (a temporary file next to the target, flushed and
// renamed), read only from regular files of bounded size, and the temporary files of saves
// that were killed removed by the next save to the same path (docs/checkpoint.md).
#pragma once

#include <stdint.h>

#include <string>
#include <vector>

#include "../core/host_memory.h"

namespace sph {

// Writes `bytes` to `path` atomically: a crash leaves the old file or the new one. Throws
// Error(InvalidArgument) naming the step that failed; the temporary file is removed then.
void write_file_atomically(const std::string& path, const HostVector<uint8_t>& bytes);

// Moves the file at `from` to `to` in one step (a rename in one directory; an existing `to` is
// replaced). Throws Error(InvalidArgument) naming both when it fails; nothing moved then.
void move_file(const std::string& from, const std::string& to);

// Reads a whole regular file of at most 256 GiB; anything else (a directory, device, FIFO,
// socket, or a larger file) is refused with Error(InvalidArgument) before it is read.
HostVector<uint8_t> read_checkpoint_file(const char* path);

}  // namespace sph
