/*
 * Loading a private copy of a libretro core, and running its frames.
 */
#define _GNU_SOURCE
#include "callbacks.h"
#include "isolate.h"
#include "video.h"

#include <dlfcn.h>
#include <errno.h>
#include <fcntl.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

_Thread_local rk_core *rk_current;

void rk_enter(rk_core *core) { rk_current = core; }
void rk_leave(void) { rk_current = NULL; }

void rk_set_error(rk_core *core, const char *fmt, ...) {
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(core->error, sizeof core->error, fmt, ap);
    va_end(ap);
}

/* ---- loading a private copy ---------------------------------------------------------------- */

/* Copies the core to a temporary file, unlinks it at once (a crash can leave no file behind)
 * and returns its open descriptor, which names the copy for dlopen. */
static int copy_to_private_file(rk_core *core, const char *path) {
    const char *tmp = getenv("TMPDIR");
    char name[4096];
    snprintf(name, sizeof name, "%s/retrokit-core-XXXXXX.so", tmp && *tmp ? tmp : "/tmp");
    int dst = mkstemps(name, 3);
    if (dst < 0) {
        rk_set_error(core, "cannot create a private copy of the core in %s: %s", name, strerror(errno));
        return -1;
    }
    unlink(name);
    int src = open(path, O_RDONLY | O_CLOEXEC);
    if (src < 0) {
        rk_set_error(core, "cannot open the core %s: %s", path, strerror(errno));
        close(dst);
        return -1;
    }
    char buf[1 << 16];
    ssize_t n;
    int rc = 0;
    while ((n = read(src, buf, sizeof buf)) > 0) {
        if (write(dst, buf, (size_t)n) != n) {
            rc = -1;
            break;
        }
    }
    if (n < 0) rc = -1;
    if (rc) rk_set_error(core, "cannot copy the core %s to %s: %s", path, name, strerror(errno));
    close(src);
    if (rc) {
        close(dst);
        return -1;
    }
    return dst;
}

#define RESOLVE(field, name)                                                      \
    do {                                                                          \
        *(void **)(&core->api.field) = dlsym(core->handle, name);                 \
        if (!core->api.field) {                                                   \
            rk_set_error(core, "%s is not a libretro core: it has no %s", path, name); \
            return -1;                                                            \
        }                                                                         \
    } while (0)

static int resolve(rk_core *core, const char *path) {
    RESOLVE(init, "retro_init");
    RESOLVE(deinit, "retro_deinit");
    RESOLVE(api_version, "retro_api_version");
    RESOLVE(get_system_info, "retro_get_system_info");
    RESOLVE(get_system_av_info, "retro_get_system_av_info");
    RESOLVE(set_environment, "retro_set_environment");
    RESOLVE(set_video_refresh, "retro_set_video_refresh");
    RESOLVE(set_audio_sample, "retro_set_audio_sample");
    RESOLVE(set_audio_sample_batch, "retro_set_audio_sample_batch");
    RESOLVE(set_input_poll, "retro_set_input_poll");
    RESOLVE(set_input_state, "retro_set_input_state");
    RESOLVE(set_controller_port_device, "retro_set_controller_port_device");
    RESOLVE(reset, "retro_reset");
    RESOLVE(run, "retro_run");
    RESOLVE(serialize_size, "retro_serialize_size");
    RESOLVE(serialize, "retro_serialize");
    RESOLVE(unserialize, "retro_unserialize");
    RESOLVE(load_game, "retro_load_game");
    RESOLVE(unload_game, "retro_unload_game");
    RESOLVE(get_memory_data, "retro_get_memory_data");
    RESOLVE(get_memory_size, "retro_get_memory_size");
    return 0;
}

int rk_core_open(rk_core *core, const char *path, const char *system_dir, const char *save_dir) {
    int fd = copy_to_private_file(core, path);
    if (fd < 0) return -1;
    /* The copy is a file of its own, so the loader maps it anew instead of handing back a
     * library another emulator already uses; its descriptor stays open while the core is
     * loaded, so no later copy gets the same /proc name while this one is mapped. */
    char private_path[64];
    snprintf(private_path, sizeof private_path, "/proc/self/fd/%d", fd);
    core->copy_fd = fd + 1;
    core->handle = dlopen(private_path, RTLD_NOW | RTLD_LOCAL);
    if (!core->handle) {
        rk_set_error(core, "cannot load the core %s: %s", path, dlerror());
        return -1;
    }
    if (resolve(core, path)) return -1;
    rk_rand_seed(&core->rand, 1); /* as a fresh process's libc */
    if (rk_isolate_core(core) < 0) {
        rk_set_error(core, "cannot inspect the loaded core %s to give it a random state of its own", path);
        return -1;
    }
    if (core->api.api_version() != RK_RETRO_API_VERSION) {
        rk_set_error(core, "%s implements libretro API version %u; retrokit needs version %d", path,
                  core->api.api_version(), RK_RETRO_API_VERSION);
        return -1;
    }
    core->system_dir = strdup(system_dir);
    core->save_dir = strdup(save_dir);
    core->pixel_format = RK_RETRO_PIXEL_FORMAT_0RGB1555;
    core->av_enable = 1 | 2; /* video and audio, until a run says otherwise */
    rk_enter(core);
    core->api.set_environment(rk_cb_environment);
    core->api.set_video_refresh(rk_cb_video);
    core->api.set_audio_sample(rk_cb_audio_sample);
    core->api.set_audio_sample_batch(rk_cb_audio_batch);
    core->api.set_input_poll(rk_cb_input_poll);
    core->api.set_input_state(rk_cb_input_state);
    core->api.init();
    rk_leave();
    core->initialized = 1;
    return 0;
}

static int load_game(rk_core *core, const char *path, const void *data, size_t size) {
    struct rk_retro_game_info info = {path, data, size, NULL};
    rk_enter(core);
    bool ok = core->api.load_game(&info);
    if (ok) {
        core->game_loaded = 1;
        core->api.get_system_av_info(&core->av);
    }
    rk_leave();
    if (!ok) {
        rk_set_error(core, "the core refused to load %s", path);
        return -1;
    }
    return 0;
}

int rk_core_load_game(rk_core *core, const char *path, const void *data, size_t size, int keep) {
    if (keep) {
        core->game_path = strdup(path);
        core->game_data = size ? malloc(size) : NULL;
        if (!core->game_path || (size && !core->game_data)) {
            rk_set_error(core, "cannot keep a copy of %s (%zu bytes) to reload it", path, size);
            return -1;
        }
        if (size) memcpy(core->game_data, data, size);
        core->game_size = size;
    }
    return load_game(core, path, data, size);
}

int rk_core_reload_game(rk_core *core) {
    if (!core->game_path) {
        rk_set_error(core, "the game was loaded without keeping a copy, so it cannot be reloaded");
        return -1;
    }
    rk_enter(core);
    core->api.unload_game();
    rk_leave();
    core->game_loaded = 0;
    /* The last frame may have gone with the game: until the next frame, the screen is black. */
    core->frame_data = NULL;
    return load_game(core, core->game_path, core->game_data, core->game_size);
}

void rk_core_close(rk_core *core) {
    if (core->handle) {
        rk_enter(core);
        if (core->game_loaded) core->api.unload_game();
        if (core->initialized) core->api.deinit();
        rk_leave();
        dlclose(core->handle);
        core->handle = NULL;
    }
    if (core->copy_fd) close(core->copy_fd - 1);
    core->copy_fd = 0;
    core->game_loaded = core->initialized = 0;
    rk_free_options(core);
    for (int i = 0; i < 2 * core->n_overrides; i++) free(core->overrides[i]);
    free(core->overrides);
    core->overrides = NULL;
    core->n_overrides = 0;
    for (int i = 0; i < core->n_log; i++) free(core->log[i].text);
    core->n_log = 0;
    rk_prep_free(core->prep);
    core->prep = NULL;
    free(core->audio);
    core->audio = NULL;
    core->audio_len = core->audio_cap = 0;
    free(core->system_dir);
    free(core->save_dir);
    core->system_dir = core->save_dir = NULL;
    free(core->game_path);
    free(core->game_data);
    core->game_path = NULL;
    core->game_data = NULL;
    core->game_size = 0;
}

/* ---- running frames with sticky actions -------------------------------------------------------- */

static uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

static uint64_t splitmix64(uint64_t *x) {
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* xoshiro256**: small, fast, and the same on every platform. */
static uint64_t next_u64(uint64_t s[4]) {
    uint64_t result = rotl(s[1] * 5, 7) * 9;
    uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

void rk_core_seed(rk_core *core, double prob, uint64_t seed) {
    core->sticky_prob = prob;
    for (int i = 0; i < 4; i++) core->rng[i] = splitmix64(&seed);
}

void rk_core_run(rk_core *core, const uint16_t *actions, int n_ports, int frames, int after) {
    uint16_t action[RK_MAX_PORTS] = {0};
    memcpy(action, actions, sizeof(uint16_t) * (size_t)n_ports);
    int stick = 0;
    if (core->have_held && core->sticky_prob > 0.0) {
        double u = (double)(next_u64(core->rng) >> 11) * 0x1.0p-53;
        stick = u < core->sticky_prob;
    }
    core->last_stuck = stick && frames > 0;
    /* With max_pool the observation is the max of the last two frames: both are seen. */
    int keep = core->prep && rk_prep_wants_previous(core->prep), seen = keep ? 2 : 1;
    rk_enter(core);
    for (int f = 0; f < frames; f++) {
        /* The first frame of a new action keeps the last applied one when it sticks. */
        memcpy(core->buttons, (f == 0 && stick) ? core->held : action, sizeof core->buttons);
        int all = core->video_frames == RK_VIDEO_ALL;
        core->av_enable = (all || (core->video_frames == RK_VIDEO_LAST && f >= frames - seen)) |
                          (all || core->capture_audio) << 1;
        core->api.run();
        core->frame++;
        /* Keep the frame before the step's last, before the last overwrites it. A step run one frame a
         * call keeps each of its frames but the planned last: if the scenario ends the episode early,
         * the observation is the max of the frame that ended it and the one before, as MaxAndSkip's. */
        if (keep && f == frames - (after > 0 ? 1 : 2)) rk_prep_keep(core->prep, core);
    }
    rk_leave();
    if (frames > 0) {
        memcpy(core->held, core->buttons, sizeof core->held);
        core->have_held = 1;
    }
}

int rk_core_screen_into(rk_core *core, uint8_t *dst, unsigned width, unsigned height) {
    if (core->prep) {
        rk_prep_observe(core->prep, core, dst);
        return 1;
    }
    if (!core->frame_data || core->frame_width != width || core->frame_height != height) return 0;
    return rk_frame_to_rgb(core->frame_data, core->frame_pitch, width, height, core->pixel_format, dst) == 0;
}
