/*
 * One libretro core, privately loaded, and the frontend state it talks to.
 *
 * libretro callbacks carry no context pointer, so the emulator a callback
 * belongs to is the one the calling thread entered last (rk_current). Each
 * emulator has its own copy of the core's shared library, so two emulators
 * never share a core's globals, and each is used by one thread at a time.
 */
#ifndef RETROKIT_CORE_H
#define RETROKIT_CORE_H

#include <stdatomic.h>
#include <stddef.h>
#include <stdint.h>

#include "libretro_api.h"
#include "preprocess.h"

#define RK_MAX_PORTS 8
#define RK_MAX_LOG 256
#define RK_MAX_MAPS 64

/* Which frames of a run the core is told to draw (GET_AUDIO_VIDEO_ENABLE). */
enum { RK_VIDEO_ALL, RK_VIDEO_LAST, RK_VIDEO_NONE };

typedef struct {
    char *key;
    char *desc;
    char *value;   /* current value, always a valid string; "" when left unanswered */
    char **allowed;
    int n_allowed;
} rk_option;

typedef struct {
    uint64_t flags;
    void *ptr;
    size_t offset, start, select, disconnect, len;
    char addrspace[32];
} rk_memmap;

typedef struct {
    int level;
    char *text;
} rk_log_entry;

/* glibc's random() state (TYPE_3): one per emulator, see isolate.c. */
#define RK_RAND_DEGREE 31
#define RK_RAND_SEP 3
typedef struct {
    int32_t state[RK_RAND_DEGREE];
    int front, rear;
} rk_rand;

/* The core's entry points, resolved with dlsym. */
typedef struct {
    void (*init)(void);
    void (*deinit)(void);
    unsigned (*api_version)(void);
    void (*get_system_info)(struct rk_retro_system_info *);
    void (*get_system_av_info)(struct rk_retro_system_av_info *);
    void (*set_environment)(rk_retro_environment_t);
    void (*set_video_refresh)(rk_retro_video_refresh_t);
    void (*set_audio_sample)(rk_retro_audio_sample_t);
    void (*set_audio_sample_batch)(rk_retro_audio_sample_batch_t);
    void (*set_input_poll)(rk_retro_input_poll_t);
    void (*set_input_state)(rk_retro_input_state_t);
    void (*set_controller_port_device)(unsigned, unsigned);
    void (*reset)(void);
    void (*run)(void);
    size_t (*serialize_size)(void);
    bool (*serialize)(void *, size_t);
    bool (*unserialize)(const void *, size_t);
    bool (*load_game)(const struct rk_retro_game_info *);
    void (*unload_game)(void);
    void *(*get_memory_data)(unsigned);
    size_t (*get_memory_size)(unsigned);
} rk_core_api;

typedef struct rk_core {
    void *handle;
    int copy_fd; /* the unlinked private copy's descriptor + 1 (0: none), open while loaded */
    rk_core_api api;
    int initialized;
    int game_loaded;
    /* The game as it was loaded, kept (when asked) so that rk_core_reload_game can load it again. */
    char *game_path;
    void *game_data;
    size_t game_size;

    char *system_dir;
    char *save_dir;

    /* Core options: declared by the core, overridable per emulator. */
    rk_option *options;
    int n_options;
    char **overrides; /* key, value pairs given before the core declared its options */
    int n_overrides;
    int options_updated;

    /* Video: the last frame the core handed over (not copied). */
    const void *frame_data;
    unsigned frame_width, frame_height;
    size_t frame_pitch;
    int pixel_format;
    struct rk_retro_system_av_info av;

    /* Input: one RetroPad bit mask per port. */
    uint16_t buttons[RK_MAX_PORTS];
    uint16_t held[RK_MAX_PORTS];
    int have_held;
    int last_stuck; /* whether the last run's first frame kept the previous buttons */
    double sticky_prob;
    uint64_t rng[4];
    int n_ports;

    /* What GET_AUDIO_VIDEO_ENABLE answers: a frame nobody sees needs no
     * drawing, audio nobody captures no mixing (cores that ask skip them). */
    int video_frames; /* RK_VIDEO_*, for the frames of each run */
    int av_enable;    /* the answer for the frame running now */
    uint64_t av_asked; /* how often the core asked */
    uint64_t av_drawn; /* how often it was told to draw the frame */

    /* The observation's preprocessing, or NULL for the plain RGB screen. */
    rk_prep *prep;

    /* Audio, captured only when asked. */
    int capture_audio;
    int16_t *audio;
    size_t audio_len, audio_cap;

    rk_memmap maps[RK_MAX_MAPS];
    int n_maps;

    /* Log lines are queued while the core runs and flushed under the GIL. */
    rk_log_entry log[RK_MAX_LOG];
    int n_log;
    int log_dropped;

    rk_rand rand; /* what the core's rand() draws from */
    uint64_t frame;
    atomic_int busy;
    char error[512];
} rk_core;

/* Loading and unloading. Each returns 0 on success, else fills core->error. */
int rk_core_open(rk_core *core, const char *path, const char *system_dir, const char *save_dir);
void rk_core_close(rk_core *core);
/* keep: hold a copy of the game, for rk_core_reload_game. */
int rk_core_load_game(rk_core *core, const char *path, const void *data, size_t size, int keep);
/* Unload the game and load the kept copy again: the core rebuilds everything it made for the game (its
 * memory too, so pointers from get_memory_data and the memory maps may change). Fails if nothing is kept;
 * after a failed load no game is loaded. */
int rk_core_reload_game(rk_core *core);
int rk_core_set_option(rk_core *core, const char *key, const char *value);

/* Running: enter/leave set the calling thread's current core for the callbacks. */
void rk_enter(rk_core *core);
void rk_leave(void);
/* Run `frames` frames; `after` is how many frames of the same step the caller will run after these
 * (one call per frame when a scenario is asked after every frame), so that with max_pool the frame
 * before the step's last is kept wherever it runs. */
void rk_core_run(rk_core *core, const uint16_t *actions, int n_ports, int frames, int after);
void rk_core_seed(rk_core *core, double prob, uint64_t seed);
/* Convert the last frame into an RGB buffer of height x width x 3, if the
 * frame has that size; returns whether it did. With a preprocessor, make the
 * observation into dst instead (of its size; width and height are unused). */
int rk_core_screen_into(rk_core *core, uint8_t *dst, unsigned width, unsigned height);

#endif
