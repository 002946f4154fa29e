/* SPDX-License-Identifier: MIT */
/*
 * sph_vdb.h - optional OpenVDB helpers for sph (library libsph_vdb, target sph::sph_vdb).
 *
 * Kept apart from sph_c.h so that the core library and its users never depend on OpenVDB.
 * Built when OpenVDB is found (CMake option SPH_WITH_OPENVDB). Same conventions as sph_c.h.
 */
#ifndef SPH_VDB_H
#define SPH_VDB_H

#include "sph_c.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Loads a level-set FloatGrid from a .vdb file into a new SDF asset of `context`: the grid's
 * active voxels (plus one voxel of margin) become a dense grid whose index_to_local is the
 * grid's linear index-to-world transform, so the asset's local frame is the file's world frame.
 * Voxels outside the narrow band take the grid's values there (plus or minus the band width), so
 * deeper inside than the band the distance is flat and has no gradient: a particle that gets
 * there (fluid placed inside the collider, a collider moved into fluid) is not pushed out. Give
 * a collider an interior band as deep as it is thick (a wider half-width, or a filled interior
 * when the level set is made from a mesh).
 * grid_name selects a grid; NULL or "" takes the first float level set in the file.
 * Errors: INVALID_HANDLE (NULL context), INVALID_ARGUMENT (NULL path or out; the file cannot be opened, is
 * not a regular file, is not a VDB file or ends early; no such grid; the grid is not a float level set; a
 * non-linear transform; a level set with no active voxels, such as sph-run's surface of a frame without
 * particles), CAPACITY (the dense grid would exceed 2^31 voxels), and those of sph_sdf_create. On failure
 * *out is unchanged and sph_vdb_get_last_error() explains. Thread-safe. A file that ends early leaks
 * the nodes OpenVDB 10 read of it before the end (about 0.3 MB a file, inside OpenVDB's reader).
 */
SPH_API sph_result SPH_CALL sph_vdb_load_sdf(sph_context* context, const char* path, const char* grid_name,
                                             sph_sdf** out);

/** The message of the last failed sph_vdb_ call on this thread, or "" after a success. */
SPH_API const char* SPH_CALL sph_vdb_get_last_error(void);

#ifdef __cplusplus
}
#endif

#endif /* SPH_VDB_H */
