// SPDX-License-Identifier: MIT
// Checkpoints of a distributed world (include/sph_mpi.h): one file per rank in the checkpoint
// format (a rank's part: its particles with their sort keys, its copy of the scene), staged and
// renamed to a name of its content once every rank has written its own, and a manifest rank 0
// writes last, the one step that replaces a set (rank_manifest.h); loaded on the saved rank count or on
// another (rank_part_join.h). Every step where one rank can fail on its own (a file, an allocation, a damaged
// or mismatched file) is agreed between the ranks (core/rank_agreement.h): each call succeeds on every rank
// or fails on every rank, a load creates no world and a restore leaves the world as it was.
#include <algorithm>
#include <cmath>
#include <cstdio>
#include <cstring>
#include <memory>
#include <string>
#include <vector>

#if defined(_WIN32)
#include <windows.h>
#else
#include <sys/stat.h>
#endif

#include "../capi/checkpoint_files.h"
#include "../capi/guard.h"
#include "../capi/handles.h"
#include "../core/byte_io.h"
#include "../core/checkpoint.h"
#include "../core/rank_agreement.h"
#include "../core/slab_decomposition.h"
#include "../factory/backend_factory.h"
#include "mpi_transport.h"
#include "mpi_world.h"
#include "rank_manifest.h"
#include "rank_part_join.h"
#include "sph_mpi.h"

using sph::Error;
using sph::Status;

namespace sph {
namespace {

void require_path(const char* path) {
  if (!path) throw Error(Status::InvalidArgument, "path: is NULL");
  if (!*path) throw Error(Status::InvalidArgument, "path: is empty");
}

// COLLECTIVE, after an agreement that every rank's path is one: the same path on every rank (its
// FNV-1a hash compared over the ranks). A rank that named another set would save
// its file where the manifest does not look, or load another world's part.
void require_same_path(const RankTransport& ranks, const char* path) {
  Fnv1a64 h;
  h.add(path, std::strlen(path));
  const uint64_t hash = h.value();
  int64_t value;
  std::memcpy(&value, &hash, sizeof value);
  bool same = true;
  compare_over_ranks(ranks, &value, 1, &same);
  if (!same)
    throw Error(Status::InvalidArgument, std::string("path: '") + path +
                                             "' on this rank and another on another rank: every rank must "
                                             "name the same checkpoint");
}

// A rank's entry as it travels to rank 0.
RankBytes pack_entry(const RankFileEntry& e) {
  ByteWriter w;
  w.u32(e.particles);
  w.u32(e.counters.ghosts);
  w.u32(e.counters.migrated_in);
  w.u32(e.counters.migrated_out);
  w.u64(e.size);
  w.u64(e.hash);
  w.bytes(e.name.data(), e.name.size());
  return RankBytes(w.buffer().begin(), w.buffer().end());
}

RankFileEntry unpack_entry(const RankBytes& b) {
  ByteReader r(b.data(), b.size(), "a rank's manifest entry");
  RankFileEntry e;
  e.particles = r.u32();
  e.counters.ghosts = r.u32();
  e.counters.migrated_in = r.u32();
  e.counters.migrated_out = r.u32();
  e.size = r.u64();
  e.hash = r.u64();
  while (r.remaining() > 0) e.name.push_back(static_cast<char>(r.u8()));
  return e;
}

// Where a rank's file waits until every rank has written its own.
std::string staged_path(const std::string& path, int rank) {
  return rank_file_path(path, staged_rank_file_name(path, rank));
}

// Writes this rank's file under its staged name; returns its manifest entry (the name the file
// will have once every rank has staged its own).
RankFileEntry stage_rank(const sph_world* world, const RankTransport& ranks, const std::string& path) {
  CheckpointOrigin origin;
  origin.backend = static_cast<uint32_t>(world->context->backend);
  origin.library_version = SPH_VERSION;
  origin.rank_part = true;
  const HostVector<uint8_t> bytes = write_checkpoint(*world->world, origin);
  write_file_atomically(staged_path(path, ranks.rank()), bytes);
  RankFileEntry e;
  e.particles = world->world->particle_count();
  e.counters = world->world->backend().distributed_state().counters;
  e.size = bytes.size();
  e.hash = file_hash(bytes);
  e.name = rank_file_name(path, ranks.rank(), e.hash);
  return e;
}

// Removes `file` if it is a regular file (best effort: never a directory or link a test or user
// put there).
void remove_regular_file(const std::string& file) {
#if defined(_WIN32)
  (void)DeleteFileA(file.c_str());  // (files only)
#else
  struct stat st;
  if (::lstat(file.c_str(), &st) == 0 && S_ISREG(st.st_mode)) (void)std::remove(file.c_str());
#endif
}

// A failed save's staged file.
void remove_staged(const std::string& path, int rank) {
  if (!path.empty()) remove_regular_file(staged_path(path, rank));
}

// The files of the set a save to `path` replaces that this rank removes once the new manifest is
// in place: its own rank's, and on rank 0 those of ranks past this rank count; only names this
// library gives rank files (is_rank_file_name). Best effort: no manifest there, or a damaged or
// foreign one, gives none and the save goes on (those files stay).
std::vector<std::string> replaced_files(const std::string& path, int rank, int size) {
  std::vector<std::string> files;
  try {
    const HostVector<uint8_t> bytes = read_checkpoint_file(path.c_str());
    const RankManifest m = read_rank_manifest(bytes.data(), bytes.size());
    for (size_t k = 0; k < m.ranks.size(); ++k) {
      const int r = static_cast<int>(k);
      if ((r == rank || (rank == 0 && r >= size)) && is_rank_file_name(path, r, m.ranks[k].name))
        files.push_back(rank_file_path(path, m.ranks[k].name));
    }
  } catch (const Error&) {
    files.clear();
  }
  return files;
}

// Rank k's file of the set at `manifest_path`, checked against the manifest's size and hash.
HostVector<uint8_t> read_rank_file(const std::string& manifest_path, const RankManifest& m, uint32_t k) {
  const RankFileEntry& entry = m.ranks[k];
  const std::string file = rank_file_path(manifest_path, entry.name);
  HostVector<uint8_t> bytes = read_checkpoint_file(file.c_str());
  if (bytes.size() != entry.size || file_hash(bytes) != entry.hash)
    throw Error(Status::CorruptData, "manifest: rank " + std::to_string(k) + "'s file '" + file + "' has " +
                                         std::to_string(bytes.size()) + " bytes" +
                                         (bytes.size() == entry.size ? " and another hash" : "") +
                                         "; the manifest '" + manifest_path + "' lists " +
                                         std::to_string(entry.size) +
                                         " bytes and its hash (a file of another save, or damaged)");
  return bytes;
}

void check_part_count(const std::string& manifest_path, const RankManifest& m, uint32_t k, size_t count) {
  if (count != m.ranks[k].particles)
    throw Error(Status::CorruptData, "manifest: rank " + std::to_string(k) + "'s file '" +
                                         rank_file_path(manifest_path, m.ranks[k].name) + "' holds " +
                                         std::to_string(count) + " particles, the manifest " +
                                         std::to_string(m.ranks[k].particles));
}

// This rank's part of the world saved at `path`, attached to `ranks`; nothing else changes. On
// the rank count that saved it, each rank reads its own file and keeps the saved slabs; on
// another, each reads a block of the files (rank_part_join.h) and the first frame cuts anew.
std::unique_ptr<World> load_rank(sph_context* context, const std::shared_ptr<const RankTransport>& ranks,
                                 const char* path) {
  require_path(path);
  const std::string manifest_path = path;
  const HostVector<uint8_t> manifest_bytes = read_checkpoint_file(path);
  RankManifest m;
  try {
    m = read_rank_manifest(manifest_bytes.data(), manifest_bytes.size());
  } catch (const Error& e) {
    throw Error(e.status(), std::string(e.what()) + " (file '" + manifest_path + "')");
  }
  const uint32_t saved = static_cast<uint32_t>(m.ranks.size());
  const bool same_count = saved == static_cast<uint32_t>(ranks->size());
  const RankFileBlock block = same_count ? RankFileBlock{static_cast<uint32_t>(ranks->rank()),
                                                         static_cast<uint32_t>(ranks->rank()) + 1u}
                                         : rank_file_block(saved, ranks->rank(), ranks->size());
  // A rank that takes no file reads the next rank's for the scene (every file holds it alike).
  const uint32_t base = std::min(block.first, saved - 1u);
  const bool keep_own = block.first < block.last;
  std::vector<CheckpointPart> others;
  for (uint32_t k = block.first + 1u; k < block.last; ++k) {
    const HostVector<uint8_t> bytes = read_rank_file(manifest_path, m, k);
    try {
      others.push_back(read_checkpoint_part(bytes.data(), bytes.size()));
    } catch (const Error& e) {
      throw Error(e.status(),
                  std::string(e.what()) + " (file '" + rank_file_path(manifest_path, m.ranks[k].name) + "')");
    }
    check_part_count(manifest_path, m, k, others.back().particles.id.size());
  }
  const HostVector<uint8_t> bytes = read_rank_file(manifest_path, m, base);
  const std::string file = rank_file_path(manifest_path, m.ranks[base].name);
  DistributedOptions options;
  options.rebalance_threshold = m.rebalance_percent / 100.0;
  std::unique_ptr<World> world;
  try {
    world = read_checkpoint(
        bytes.data(), bytes.size(),
        [&](const WorldConfig& config) {
          std::unique_ptr<Backend> b =
              make_backend(context->backend, config, context->device_ordinal, context->cpu_workers,
                           context->cpu_tasks, context->cuda_tuning);
          b->attach_ranks(ranks, options);
          return b;
        },
        true,
        [&](CheckpointPart& part) {
          check_part_count(manifest_path, m, base, part.particles.id.size());
          if (!same_count) join_rank_parts(part, keep_own, others);
        });
  } catch (const Error& e) {
    throw Error(e.status(), std::string(e.what()) + " (file '" + file + "')");
  }
  DistributedState state = m.state;
  if (same_count) {
    const RankFileEntry& mine = m.ranks[base];
    state.counters.ghosts = mine.counters.ghosts;
    state.counters.migrated_in = mine.counters.migrated_in;
    state.counters.migrated_out = mine.counters.migrated_out;
  } else {
    // The saved slabs do not fit this rank count: one slab until the first frame cuts (as a new
    // world's first frame does); the rank's migration counters start at 0.
    const SlabDecomposition whole(ranks->size());
    state.cuts = whole.cuts();
    state.cut = false;
    state.counters.ghosts = 0;
    state.counters.migrated_in = 0;
    state.counters.migrated_out = 0;
  }
  world->backend().restore_distributed_state(state);
  return world;
}

}  // namespace
}  // namespace sph

extern "C" {

SPH_API sph_result SPH_CALL sph_mpi_world_save_file(const sph_world* world, const char* path) {
  return sph::guarded("sph_mpi_world_save_file", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);
    const sph::RankTransport& ranks = sph::ranks_of(world);
    const std::string target = path ? path : "";
    sph::RankBytes mine;
    std::vector<sph::RankBytes> entries;
    std::vector<std::string> replaced;
    std::string file;  // this rank's file of the new set
    // Three agreed phases: every rank stages its file; every rank renames its staged file to its
    // hashed name (a name the current manifest does not use unless the bytes are the same);
    // rank 0 replaces the manifest, the one step that switches sets. Then each rank removes its
    // file of the old set. A failure (or a crash) before the manifest is replaced leaves the
    // old set whole and named by its manifest.
    sph::agreed(ranks, [&] {
      sph::WorldLock::require_device_not_lost(world);
      sph::require_path(path);
    });
    sph::require_same_path(ranks, path);
    try {
      sph::agreed(ranks, [&] {
        replaced = sph::replaced_files(target, ranks.rank(), ranks.size());
        const sph::RankFileEntry e = sph::stage_rank(world, ranks, target);
        file = sph::rank_file_path(target, e.name);
        mine = sph::pack_entry(e);
      });
      entries = ranks.gather(mine, 0);
    } catch (...) {
      sph::remove_staged(target, ranks.rank());
      throw;
    }
    bool moved = false;
    try {
      sph::agreed(ranks, [&] {
        sph::move_file(sph::staged_path(target, ranks.rank()), file);
        moved = true;
      });
      sph::agreed(ranks, [&] {
        if (ranks.rank() != 0) return;
        sph::RankManifest m;
        m.state = world->world->backend().distributed_state();
        m.rebalance_percent = static_cast<uint32_t>(std::lround(m.state.rebalance_threshold * 100.0));
        for (const sph::RankBytes& b : entries) {
          m.ranks.push_back(sph::unpack_entry(b));
          m.particles += m.ranks.back().particles;
        }
        sph::write_file_atomically(target, sph::write_rank_manifest(m));
      });
    } catch (...) {
      // The old manifest still names the old set: take back what this save put beside it.
      if (!moved)
        sph::remove_staged(target, ranks.rank());
      else if (std::find(replaced.begin(), replaced.end(), file) == replaced.end())
        sph::remove_regular_file(file);
      throw;
    }
    for (const std::string& old : replaced)
      if (old != file) sph::remove_regular_file(old);
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_mpi_world_load_file(sph_context* context, int32_t comm, const char* path,
                                                    sph_world** out) {
  return sph::guarded("sph_mpi_world_load_file", context, [&] {
    // The communicator first (every rank), then every check and the load agreed, as
    // sph_mpi_world_create does: a rank refused alone does not leave the others in a collective.
    auto ranks = std::make_shared<sph::MpiTransport>(MPI_Comm_f2c(static_cast<MPI_Fint>(comm)));
    std::unique_ptr<sph::ContextHold> hold;
    sph::agreed(*ranks, [&] {
      hold = std::make_unique<sph::ContextHold>(context);
      if (!out) throw Error(Status::InvalidArgument, "out: is NULL");
      sph::require_path(path);
    });
    sph::require_same_path(*ranks, path);
    std::unique_ptr<sph_world> world;
    sph::agreed(*ranks, [&] {
      std::unique_ptr<sph::World> loaded = sph::load_rank(hold->get(), ranks, path);
      world = std::make_unique<sph_world>();
      world->context = hold->get();
      world->world = std::move(loaded);
    });
    *out = sph::publish_on_every_rank(*ranks, std::move(world));
    return SPH_OK;
  });
}

SPH_API sph_result SPH_CALL sph_mpi_world_restore_file(sph_world* world, const char* path) {
  return sph::guarded("sph_mpi_world_restore_file", sph::context_of(world), [&] {
    sph::require_world(world);
    sph::WorldLock lock(world, sph::WorldLock::kAgreeDeviceLoss);
    const sph::RankTransport& ranks = sph::ranks_of(world);
    const std::shared_ptr<const sph::RankTransport> shared = world->world->backend().shared_rank_transport();
    std::unique_ptr<sph::World> loaded;
    sph::agreed(ranks, [&] {
      sph::WorldLock::require_device_not_lost(world);
      sph::require_path(path);
    });
    sph::require_same_path(ranks, path);
    // Built whole beside the world's state, swapped in once every rank has built its own.
    sph::agreed(ranks, [&] {
      loaded = sph::load_rank(world->context, shared, path);
      // No id the world issued is issued again (sph_world_restore's rule).
      loaded->keep_issued_ids(*world->world);
    });
    loaded->backend().continue_data_epoch(world->world->backend());
    world->world.swap(loaded);
    return SPH_OK;
  });
}

}  // extern "C"
