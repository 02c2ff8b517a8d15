/* vfield.h: the C entry point of libvfield, for hosts that load the library at
 * run time (dlopen + dlsym). Every function is safe to call with a session that
 * failed to open (NULL); errors are returned as codes with a one-line message.
 *
 *   vfield_session* s = vfield_open("cloud.json", err, sizeof err);
 *   vfield_step_to(s, 12, err, sizeof err);
 *   double d = vfield_density_sample(s, x, y, z);
 *   vfield_close(s);
 */
#ifndef VFIELD_H
#define VFIELD_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

typedef struct vfield_session vfield_session;

/* The version of this interface; a host checks it before using the rest. */
#define VFIELD_C_API_VERSION 1
int vfield_api_version(void);

/* Opens a scene and builds its fields. NULL on failure, with the reason in error. */
vfield_session* vfield_open(const char* scene_path, char* error, size_t error_size);
void vfield_close(vfield_session* session);

/* Simulates forwards to frame. 0 on success, -1 on failure (reason in error). */
int vfield_step_to(vfield_session* session, int frame, char* error, size_t error_size);
int vfield_frame(const vfield_session* session);
int vfield_first_frame(const vfield_session* session);
int vfield_last_frame(const vfield_session* session);

/* Particles of the current frame: count, and xyz positions (3 x count floats,
 * world space), valid until the next step or close. */
size_t vfield_particle_count(const vfield_session* session);
const float* vfield_particle_positions(const vfield_session* session);

/* The current frame's density: a world-space trilinear sample, the active
 * voxel count, and a hash of the grid's contents (as `vfield info --checksum`). */
double vfield_density_sample(vfield_session* session, double x, double y, double z);
uint64_t vfield_density_active_voxels(vfield_session* session);
uint64_t vfield_density_checksum(vfield_session* session);
/* Writes the current frame's density and vel grids to an OpenVDB file. 0 on success. */
int vfield_density_write(vfield_session* session, const char* path, char* error, size_t error_size);

#ifdef __cplusplus
}
#endif

#endif
