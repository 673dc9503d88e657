/*
 * What a core calls back: the environment (options, log, memory maps, pixel
 * format...), video, audio and input. The calling thread's current core
 * (rk_current) says which emulator a call belongs to.
 */
#define _GNU_SOURCE
#include "callbacks.h"

#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

static char *dup_or_empty(const char *s) { return strdup(s ? s : ""); }

/* ---- the log interface ------------------------------------------------------------ */

static void queue_log(rk_core *core, int level, const char *text) {
    if (core->n_log >= RK_MAX_LOG) {
        core->log_dropped++;
        return;
    }
    size_t n = strlen(text);
    while (n > 0 && (text[n - 1] == '\n' || text[n - 1] == '\r')) n--;
    char *copy = malloc(n + 1);
    if (!copy) return;
    memcpy(copy, text, n);
    copy[n] = 0;
    core->log[core->n_log].level = level;
    core->log[core->n_log].text = copy;
    core->n_log++;
}

static void cb_log(int level, const char *fmt, ...) {
    rk_core *core = rk_current;
    if (!core) return;
    char buf[1024];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(buf, sizeof buf, fmt, ap);
    va_end(ap);
    queue_log(core, level, buf);
}

/* ---- core options -------------------------------------------------------------------- */

static rk_option *find_option(rk_core *core, const char *key) {
    for (int i = 0; i < core->n_options; i++)
        if (strcmp(core->options[i].key, key) == 0) return &core->options[i];
    return NULL;
}

static const char *find_override(rk_core *core, const char *key) {
    for (int i = 0; i < core->n_overrides; i++)
        if (strcmp(core->overrides[2 * i], key) == 0) return core->overrides[2 * i + 1];
    return NULL;
}

static int option_allows(const rk_option *opt, const char *value) {
    if (opt->n_allowed == 0) return 1;
    for (int i = 0; i < opt->n_allowed; i++)
        if (strcmp(opt->allowed[i], value) == 0) return 1;
    return 0;
}

void rk_free_options(rk_core *core) {
    for (int i = 0; i < core->n_options; i++) {
        rk_option *o = &core->options[i];
        free(o->key);
        free(o->desc);
        free(o->value);
        for (int j = 0; j < o->n_allowed; j++) free(o->allowed[j]);
        free(o->allowed);
    }
    free(core->options);
    core->options = NULL;
    core->n_options = 0;
}

/* Add one declared option; `values` holds n allowed values. The current value
 * is the user's override when the core allows it, else the default. */
static void add_option(rk_core *core, const char *key, const char *desc, const char **values, int n,
                       const char *default_value) {
    if (!key || find_option(core, key)) return;
    rk_option *grown = realloc(core->options, sizeof(rk_option) * (core->n_options + 1));
    if (!grown) return;
    core->options = grown;
    rk_option *o = &core->options[core->n_options++];
    o->key = strdup(key);
    o->desc = dup_or_empty(desc);
    o->allowed = calloc(n > 0 ? n : 1, sizeof(char *));
    o->n_allowed = n;
    for (int i = 0; i < n; i++) o->allowed[i] = strdup(values[i]);
    const char *value = default_value ? default_value : (n > 0 ? values[0] : "");
    const char *wanted = find_override(core, key);
    if (wanted && option_allows(o, wanted)) value = wanted;
    /* An empty override leaves the option unanswered (get_variable says so), as a frontend
     * that answers no option does: some cores fall back to a value none of their own
     * declares (mednafen_pce_fast's turbo delay stays 0 under stable-retro). */
    else if (wanted && !*wanted) value = "";
    o->value = strdup(value);
}

/* Legacy SET_VARIABLES: "Description; first|second|third". */
static void add_legacy_variables(rk_core *core, const struct rk_retro_variable *vars) {
    for (; vars && vars->key; vars++) {
        const char *spec = vars->value ? vars->value : "";
        const char *semi = strchr(spec, ';');
        char desc[256] = "";
        const char *list = spec;
        if (semi) {
            size_t n = (size_t)(semi - spec) < sizeof desc - 1 ? (size_t)(semi - spec) : sizeof desc - 1;
            memcpy(desc, spec, n);
            desc[n] = 0;
            list = semi + 1;
            while (*list == ' ') list++;
        }
        char *copy = strdup(list);
        const char *values[RK_RETRO_NUM_CORE_OPTION_VALUES_MAX];
        int n = 0;
        for (char *save = NULL, *tok = strtok_r(copy, "|", &save); tok && n < RK_RETRO_NUM_CORE_OPTION_VALUES_MAX;
             tok = strtok_r(NULL, "|", &save))
            values[n++] = tok;
        add_option(core, vars->key, desc, values, n, NULL);
        free(copy);
    }
}

static void add_v1_definitions(rk_core *core, const struct rk_retro_core_option_definition *defs) {
    for (; defs && defs->key; defs++) {
        const char *values[RK_RETRO_NUM_CORE_OPTION_VALUES_MAX];
        int n = 0;
        while (n < RK_RETRO_NUM_CORE_OPTION_VALUES_MAX && defs->values[n].value) {
            values[n] = defs->values[n].value;
            n++;
        }
        add_option(core, defs->key, defs->desc, values, n, defs->default_value);
    }
}

static void add_v2_definitions(rk_core *core, const struct rk_retro_core_options_v2 *opts) {
    if (!opts) return;
    for (const struct rk_retro_core_option_v2_definition *d = opts->definitions; d && d->key; d++) {
        const char *values[RK_RETRO_NUM_CORE_OPTION_VALUES_MAX];
        int n = 0;
        while (n < RK_RETRO_NUM_CORE_OPTION_VALUES_MAX && d->values[n].value) {
            values[n] = d->values[n].value;
            n++;
        }
        add_option(core, d->key, d->desc, values, n, d->default_value);
    }
}

int rk_core_set_option(rk_core *core, const char *key, const char *value) {
    rk_option *o = find_option(core, key);
    if (!o) {
        /* Not declared yet: remember it for when the core declares it. */
        for (int i = 0; i < core->n_overrides; i++) {
            if (strcmp(core->overrides[2 * i], key) == 0) {
                free(core->overrides[2 * i + 1]);
                core->overrides[2 * i + 1] = strdup(value);
                return 0;
            }
        }
        char **grown = realloc(core->overrides, sizeof(char *) * 2 * (core->n_overrides + 1));
        if (!grown) return -1;
        core->overrides = grown;
        core->overrides[2 * core->n_overrides] = strdup(key);
        core->overrides[2 * core->n_overrides + 1] = strdup(value);
        core->n_overrides++;
        return 0;
    }
    if (!option_allows(o, value)) {
        rk_set_error(core, "core option %s does not allow the value %s", key, value);
        return -1;
    }
    free(o->value);
    o->value = strdup(value);
    core->options_updated = 1;
    return 0;
}

/* ---- the environment callback ------------------------------------------------------------ */

static bool get_variable(rk_core *core, struct rk_retro_variable *var) {
    /* Genesis Plus GX dereferences the value even when we answer false, so
     * the value is always a valid string. */
    rk_option *o = var->key ? find_option(core, var->key) : NULL;
    if (o) {
        var->value = o->value;
        return option_allows(o, o->value); /* false when left unanswered (add_option) */
    }
    const char *wanted = var->key ? find_override(core, var->key) : NULL;
    var->value = wanted ? wanted : "";
    return wanted != NULL && *wanted;
}

static void set_memory_maps(rk_core *core, const struct rk_retro_memory_map *map) {
    core->n_maps = 0;
    for (unsigned i = 0; map && i < map->num_descriptors && core->n_maps < RK_MAX_MAPS; i++) {
        const struct rk_retro_memory_descriptor *d = &map->descriptors[i];
        rk_memmap *m = &core->maps[core->n_maps++];
        m->flags = d->flags;
        m->ptr = d->ptr;
        m->offset = d->offset;
        m->start = d->start;
        m->select = d->select;
        m->disconnect = d->disconnect;
        m->len = d->len;
        /* A descriptor may leave len 0 and give its size by the address bits select
         * decodes (snes9x's work RAM: 0x7E0000, select 0xFE0000, 128 KiB); size it from
         * them as Gym Retro does, or the RAM gets no view and no console address finds it. */
        if (!m->len && d->select) m->len = ((~d->select & ~d->start) + 1) & d->select;
        snprintf(m->addrspace, sizeof m->addrspace, "%s", d->addrspace ? d->addrspace : "");
    }
}

bool rk_cb_environment(unsigned cmd, void *data) {
    rk_core *core = rk_current;
    if (!core) return false;
    switch (cmd) {
    case RK_ENV_GET_OVERSCAN:
        *(bool *)data = false;
        return true;
    case RK_ENV_GET_CAN_DUPE:
        *(bool *)data = true;
        return true;
    case RK_ENV_SET_MESSAGE: {
        const struct rk_retro_message *msg = data;
        if (msg && msg->msg) queue_log(core, RK_RETRO_LOG_INFO, msg->msg);
        return true;
    }
    case RK_ENV_SET_PERFORMANCE_LEVEL:
    case RK_ENV_SET_INPUT_DESCRIPTORS:
    case RK_ENV_SET_CONTROLLER_INFO:
    case RK_ENV_SET_SUBSYSTEM_INFO:
    case RK_ENV_SET_SUPPORT_NO_GAME:
    case RK_ENV_SET_SERIALIZATION_QUIRKS:
    case RK_ENV_SET_CORE_OPTIONS_DISPLAY:
    case RK_ENV_SET_ROTATION:
        return true;
    case RK_ENV_GET_SYSTEM_DIRECTORY:
        *(const char **)data = core->system_dir;
        return true;
    case RK_ENV_GET_SAVE_DIRECTORY:
        *(const char **)data = core->save_dir;
        return true;
    case RK_ENV_SET_PIXEL_FORMAT: {
        int fmt = *(const int *)data;
        if (fmt != RK_RETRO_PIXEL_FORMAT_0RGB1555 && fmt != RK_RETRO_PIXEL_FORMAT_XRGB8888 &&
            fmt != RK_RETRO_PIXEL_FORMAT_RGB565)
            return false;
        core->pixel_format = fmt;
        return true;
    }
    case RK_ENV_GET_VARIABLE:
        return get_variable(core, data);
    case RK_ENV_SET_VARIABLES:
        add_legacy_variables(core, data);
        return true;
    case RK_ENV_GET_VARIABLE_UPDATE:
        *(bool *)data = core->options_updated != 0;
        core->options_updated = 0;
        return true;
    case RK_ENV_GET_LOG_INTERFACE:
        ((struct rk_retro_log_callback *)data)->log = cb_log;
        return true;
    case RK_ENV_SET_SYSTEM_AV_INFO:
        core->av = *(const struct rk_retro_system_av_info *)data;
        return true;
    case RK_ENV_SET_GEOMETRY:
        core->av.geometry = *(const struct rk_retro_game_geometry *)data;
        return true;
    case RK_ENV_SET_MEMORY_MAPS:
        set_memory_maps(core, data);
        return true;
    case RK_ENV_GET_LANGUAGE:
        *(unsigned *)data = 0; /* English */
        return true;
    case RK_ENV_GET_AUDIO_VIDEO_ENABLE:
        core->av_asked++;
        core->av_drawn += core->av_enable & 1;
        if (data) *(int *)data = core->av_enable;
        return true;
    case RK_ENV_GET_FASTFORWARDING:
        if (data) *(bool *)data = false;
        return true;
    case RK_ENV_GET_INPUT_BITMASKS:
        return true;
    case RK_ENV_GET_CORE_OPTIONS_VERSION:
        *(unsigned *)data = 2;
        return true;
    case RK_ENV_SET_CORE_OPTIONS:
        add_v1_definitions(core, data);
        return true;
    case RK_ENV_SET_CORE_OPTIONS_INTL:
        add_v1_definitions(core, ((const struct rk_retro_core_options_intl *)data)->us);
        return true;
    case RK_ENV_SET_CORE_OPTIONS_V2:
        add_v2_definitions(core, data);
        return true;
    case RK_ENV_SET_CORE_OPTIONS_V2_INTL:
        add_v2_definitions(core, ((const struct rk_retro_core_options_v2_intl *)data)->us);
        return true;
    case RK_ENV_GET_MESSAGE_INTERFACE_VERSION:
        *(unsigned *)data = 0;
        return true;
    case RK_ENV_GET_INPUT_MAX_USERS:
        *(unsigned *)data = (unsigned)core->n_ports;
        return true;
    default:
        return false;
    }
}

/* ---- video, audio and input callbacks ---------------------------------------------------- */

void rk_cb_video(const void *data, unsigned width, unsigned height, size_t pitch) {
    rk_core *core = rk_current;
    if (!core || !data || data == (const void *)-1) return; /* a duplicated frame keeps the last one */
    core->frame_data = data;
    core->frame_width = width;
    core->frame_height = height;
    core->frame_pitch = pitch;
}

static int append_audio(rk_core *core, const int16_t *data, size_t frames) {
    size_t need = core->audio_len + 2 * frames;
    if (need > core->audio_cap) {
        size_t cap = core->audio_cap ? core->audio_cap : 8192;
        while (cap < need) cap *= 2;
        int16_t *grown = realloc(core->audio, cap * sizeof(int16_t));
        if (!grown) return -1;
        core->audio = grown;
        core->audio_cap = cap;
    }
    memcpy(core->audio + core->audio_len, data, 2 * frames * sizeof(int16_t));
    core->audio_len = need;
    return 0;
}

void rk_cb_audio_sample(int16_t left, int16_t right) {
    rk_core *core = rk_current;
    if (core && core->capture_audio) {
        int16_t pair[2] = {left, right};
        append_audio(core, pair, 1);
    }
}

size_t rk_cb_audio_batch(const int16_t *data, size_t frames) {
    rk_core *core = rk_current;
    if (core && core->capture_audio) append_audio(core, data, frames);
    return frames;
}

void rk_cb_input_poll(void) {}

int16_t rk_cb_input_state(unsigned port, unsigned device, unsigned index, unsigned id) {
    rk_core *core = rk_current;
    if (!core || port >= (unsigned)core->n_ports || (device & 0xff) != RK_RETRO_DEVICE_JOYPAD) return 0;
    uint16_t mask = core->buttons[port];
    if (id == RK_RETRO_DEVICE_ID_JOYPAD_MASK) return (int16_t)mask;
    return id < 16 ? (int16_t)((mask >> id) & 1) : 0;
}

