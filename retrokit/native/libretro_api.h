/*
 * The part of the libretro API that retrokit's host uses, declared here.
 *
 * These constants and struct layouts are an interface between us and every
 * core, so tests/test_libretro_abi.py compiles a check of each one against
 * the reference libretro.h (Debian's retroarch-dev) when it is installed.
 */
#ifndef RETROKIT_LIBRETRO_API_H
#define RETROKIT_LIBRETRO_API_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#define RK_RETRO_API_VERSION 1
#define RK_RETRO_DEVICE_JOYPAD 1
#define RK_RETRO_DEVICE_ID_JOYPAD_MASK 256
#define RK_RETRO_MEMORY_SYSTEM_RAM 2
#define RK_RETRO_LOG_INFO 1
#define RK_RETRO_NUM_CORE_OPTION_VALUES_MAX 128

#define RK_RETRO_PIXEL_FORMAT_0RGB1555 0
#define RK_RETRO_PIXEL_FORMAT_XRGB8888 1
#define RK_RETRO_PIXEL_FORMAT_RGB565 2

#define RK_ENV_EXPERIMENTAL 0x10000
/* Environment commands, with the experimental bit where the API sets it. */
#define RK_ENV_SET_ROTATION 1
#define RK_ENV_GET_OVERSCAN 2
#define RK_ENV_GET_CAN_DUPE 3
#define RK_ENV_SET_MESSAGE 6
#define RK_ENV_SET_PERFORMANCE_LEVEL 8
#define RK_ENV_GET_SYSTEM_DIRECTORY 9
#define RK_ENV_SET_PIXEL_FORMAT 10
#define RK_ENV_SET_INPUT_DESCRIPTORS 11
#define RK_ENV_GET_VARIABLE 15
#define RK_ENV_SET_VARIABLES 16
#define RK_ENV_GET_VARIABLE_UPDATE 17
#define RK_ENV_SET_SUPPORT_NO_GAME 18
#define RK_ENV_GET_LOG_INTERFACE 27
#define RK_ENV_GET_SAVE_DIRECTORY 31
#define RK_ENV_SET_SYSTEM_AV_INFO 32
#define RK_ENV_SET_SUBSYSTEM_INFO 34
#define RK_ENV_SET_CONTROLLER_INFO 35
#define RK_ENV_SET_MEMORY_MAPS (36 | RK_ENV_EXPERIMENTAL)
#define RK_ENV_SET_GEOMETRY 37
#define RK_ENV_GET_LANGUAGE 39
#define RK_ENV_SET_SERIALIZATION_QUIRKS 44
#define RK_ENV_GET_AUDIO_VIDEO_ENABLE (47 | RK_ENV_EXPERIMENTAL)
#define RK_ENV_GET_FASTFORWARDING (49 | RK_ENV_EXPERIMENTAL)
#define RK_ENV_GET_INPUT_BITMASKS (51 | RK_ENV_EXPERIMENTAL)
#define RK_ENV_GET_CORE_OPTIONS_VERSION 52
#define RK_ENV_SET_CORE_OPTIONS 53
#define RK_ENV_SET_CORE_OPTIONS_INTL 54
#define RK_ENV_SET_CORE_OPTIONS_DISPLAY 55
#define RK_ENV_GET_MESSAGE_INTERFACE_VERSION 59
#define RK_ENV_GET_INPUT_MAX_USERS 61
#define RK_ENV_SET_CORE_OPTIONS_V2 67
#define RK_ENV_SET_CORE_OPTIONS_V2_INTL 68

struct rk_retro_variable { const char *key, *value; };
struct rk_retro_game_info { const char *path; const void *data; size_t size; const char *meta; };
struct rk_retro_system_info {
    const char *library_name, *library_version, *valid_extensions;
    bool need_fullpath, block_extract;
};
struct rk_retro_game_geometry { unsigned base_width, base_height, max_width, max_height; float aspect_ratio; };
struct rk_retro_system_timing { double fps, sample_rate; };
struct rk_retro_system_av_info { struct rk_retro_game_geometry geometry; struct rk_retro_system_timing timing; };
struct rk_retro_log_callback { void (*log)(int level, const char *fmt, ...); };
struct rk_retro_message { const char *msg; unsigned frames; };
struct rk_retro_memory_descriptor {
    uint64_t flags;
    void *ptr;
    size_t offset, start, select, disconnect, len;
    const char *addrspace;
};
struct rk_retro_memory_map { const struct rk_retro_memory_descriptor *descriptors; unsigned num_descriptors; };

struct rk_retro_core_option_value { const char *value, *label; };
struct rk_retro_core_option_definition {
    const char *key, *desc, *info;
    struct rk_retro_core_option_value values[RK_RETRO_NUM_CORE_OPTION_VALUES_MAX];
    const char *default_value;
};
struct rk_retro_core_options_intl { struct rk_retro_core_option_definition *us, *local; };
struct rk_retro_core_option_v2_definition {
    const char *key, *desc, *desc_categorized, *info, *info_categorized, *category_key;
    struct rk_retro_core_option_value values[RK_RETRO_NUM_CORE_OPTION_VALUES_MAX];
    const char *default_value;
};
struct rk_retro_core_options_v2 {
    const void *categories; /* retro_core_option_v2_category: the host shows no categories */
    struct rk_retro_core_option_v2_definition *definitions;
};
struct rk_retro_core_options_v2_intl { struct rk_retro_core_options_v2 *us, *local; };

/* Callbacks the frontend hands to the core. */
typedef bool (*rk_retro_environment_t)(unsigned cmd, void *data);
typedef void (*rk_retro_video_refresh_t)(const void *data, unsigned width, unsigned height, size_t pitch);
typedef void (*rk_retro_audio_sample_t)(int16_t left, int16_t right);
typedef size_t (*rk_retro_audio_sample_batch_t)(const int16_t *data, size_t frames);
typedef void (*rk_retro_input_poll_t)(void);
typedef int16_t (*rk_retro_input_state_t)(unsigned port, unsigned device, unsigned index, unsigned id);

#endif
