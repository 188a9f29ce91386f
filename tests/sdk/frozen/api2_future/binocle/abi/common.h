/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: types shared by the four plugin interfaces.
 *
 * Rules that hold for every interface (see also sdk/README.md):
 *
 * - Only C types cross the boundary: integers, doubles, `const char *` (UTF-8,
 *   NUL-terminated), plain structs and opaque handles. Enums travel as int32_t.
 * - No exception crosses the boundary. Every call that can fail returns a
 *   binocle_result; after a failure the host calls `last_error(instance)` to get the
 *   message (instance may be NULL for failures of `create`). The message stays valid
 *   until the next call on the same instance from the same thread.
 * - Versioning: every table starts with binocle_plugin_header. The header layout is
 *   frozen for ever. BINOCLE_ABI_VERSION changes only when an existing layout changes
 *   (a host refuses a plugin of another ABI version before calling anything but the
 *   init symbol). BINOCLE_API_VERSION grows when entries are appended to a table; a
 *   host reads only the entries that fit in header.struct_size, so an older plugin
 *   keeps working with a newer host.
 * - Threading: a plugin instance is used by one thread at a time (the host serialises
 *   calls on an instance); distinct instances may be used from distinct threads.
 *   `release_frame` of a source may be called from any thread.
 * - Units: lengths in millimetres unless the name says otherwise, angles in degrees in
 *   settings, time stamps in nanoseconds.
 */
#ifndef BINOCLE_ABI_COMMON_H
#define BINOCLE_ABI_COMMON_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

#define BINOCLE_ABI_VERSION 1u
#define BINOCLE_API_VERSION 2u

/* The one symbol every plugin exports (see binocle_plugin_init_fn). */
#define BINOCLE_PLUGIN_INIT_SYMBOL "binocle_plugin_init"

#if defined(_WIN32)
#define BINOCLE_PLUGIN_EXPORT __declspec(dllexport)
#else
#define BINOCLE_PLUGIN_EXPORT __attribute__((visibility("default")))
#endif

/* ---- Result codes ------------------------------------------------------------ */
typedef int32_t binocle_result;
enum {
    BINOCLE_OK = 0,
    BINOCLE_ERR_INVALID_ARGUMENT = 1, /* a setting or an argument is wrong          */
    BINOCLE_ERR_NOT_FOUND = 2,        /* file, device or camera not found           */
    BINOCLE_ERR_IO = 3,               /* read/write failure                         */
    BINOCLE_ERR_DEVICE = 4,           /* the hardware failed or went away           */
    BINOCLE_ERR_TIMEOUT = 5,          /* nothing arrived within the timeout         */
    BINOCLE_ERR_END_OF_STREAM = 6,    /* a finite source has no more frames         */
    BINOCLE_ERR_UNSUPPORTED = 7,      /* the request is valid but not supported     */
    BINOCLE_ERR_BUSY = 8,             /* resource in use                            */
    BINOCLE_ERR_INTERNAL = 9,         /* anything else, including caught exceptions */
    BINOCLE_ERR_VENDOR_BASE = 0x10000 /* plugins may use codes from here on         */
};

/* ---- Plugin kinds ------------------------------------------------------------ */
enum {
    BINOCLE_KIND_STEREO_SOURCE = 1,
    BINOCLE_KIND_MATCHER = 2,
    BINOCLE_KIND_CLOUD_TRANSFORM = 3,
    BINOCLE_KIND_EVALUATOR = 4
};

/* First member of every plugin table. Frozen layout. */
typedef struct binocle_plugin_header {
    uint32_t struct_size;    /* sizeof the whole table the plugin was built with */
    uint32_t abi_version;    /* BINOCLE_ABI_VERSION the plugin was built with    */
    uint32_t api_version;    /* BINOCLE_API_VERSION the plugin was built with    */
    int32_t kind;            /* BINOCLE_KIND_*                                   */
    const char *name;        /* unique plugin name, [a-z0-9_]+, used in YAML     */
    const char *version;     /* plugin's own version, free text ("1.2.0")        */
    const char *description; /* one line                                         */
} binocle_plugin_header;

/* Exported as "binocle_plugin_init". The host passes the ABI and API versions it
 * speaks; the plugin returns its static table (never freed) or NULL if it cannot
 * serve that host at all. A plugin returns its table even when the versions differ:
 * the host then compares header.abi_version with its own and refuses with both
 * numbers in the message. */
typedef const binocle_plugin_header *(*binocle_plugin_init_fn)(uint32_t host_abi_version,
                                                               uint32_t host_api_version);

/* ---- Images ------------------------------------------------------------------ */
enum {
    BINOCLE_PIXEL_GRAY8 = 1,
    BINOCLE_PIXEL_GRAY16 = 2,
    BINOCLE_PIXEL_BGR8 = 3,
    BINOCLE_PIXEL_RGB8 = 4,
    BINOCLE_PIXEL_FLOAT32 = 5, /* one float per pixel: disparity, depth            */
    BINOCLE_PIXEL_VENDOR_BASE = 0x10000
};

/* A view on pixels that somebody else owns. */
typedef struct binocle_image {
    int32_t width;        /* pixels                                              */
    int32_t height;       /* pixels                                              */
    int32_t stride_bytes; /* bytes from one row to the next, >= width * bpp      */
    int32_t format;       /* BINOCLE_PIXEL_*                                     */
    void *data;           /* first pixel of the first row                        */
} binocle_image;

/* Disparity maps are FLOAT32 images in pixels of the left (reference) image;
 * a pixel without a valid match holds BINOCLE_INVALID_DISPARITY (any value <= 0
 * counts as invalid). */
#define BINOCLE_INVALID_DISPARITY (-1.0f)

/* A named image, used for extra planes such as ground truth. */
typedef struct binocle_named_image {
    const char *name; /* e.g. "gt_disparity" (FLOAT32), "gt_valid" (GRAY8, 0/255) */
    binocle_image image;
} binocle_named_image;

/* ---- Settings ------------------------------------------------------------------
 * A plugin describes its settings with a table of binocle_param_desc; the host
 * validates the YAML block against it (unknown keys, types, ranges) and reports
 * file, line and column, so that every plugin gets the same diagnostics for free.
 * Validated values then reach `create` as binocle_param entries. */
enum {
    BINOCLE_PARAM_BOOL = 1,
    BINOCLE_PARAM_INT = 2,
    BINOCLE_PARAM_DOUBLE = 3,
    BINOCLE_PARAM_STRING = 4,
    BINOCLE_PARAM_ENUM = 5,     /* a string out of desc.choices                      */
    BINOCLE_PARAM_PATH = 6,     /* a string; relative paths are resolved by the host
                                   against the folder of the YAML file             */
    BINOCLE_PARAM_YAML = 7,     /* any YAML subtree, passed as YAML text            */
    BINOCLE_PARAM_INT_LIST = 8, /* passed as YAML text, e.g. "[1, 2]"              */
    BINOCLE_PARAM_DOUBLE_LIST = 9
};

enum {
    BINOCLE_PARAM_FLAG_REQUIRED = 1u << 0, /* no default: the YAML must set it       */
    BINOCLE_PARAM_FLAG_ODD = 1u << 1,      /* INT must be odd                         */
    BINOCLE_PARAM_FLAG_HAS_MIN = 1u << 2,  /* INT/DOUBLE: value >= min                */
    BINOCLE_PARAM_FLAG_HAS_MAX = 1u << 3,  /* INT/DOUBLE: value <= max                */
    BINOCLE_PARAM_FLAG_LIMIT = 1u << 4     /* a resource limit (memory, time): set in
                                              the rig or --set, never from a live page */
};

typedef struct binocle_param_desc {
    const char *name;          /* YAML key, snake_case with unit suffix: baseline_mm  */
    int32_t type;              /* BINOCLE_PARAM_*                                     */
    uint32_t flags;            /* BINOCLE_PARAM_FLAG_*                                */
    const char *default_value; /* as YAML text; NULL when REQUIRED                    */
    double min;                /* with HAS_MIN                                        */
    double max;                /* with HAS_MAX                                        */
    int64_t multiple_of;       /* INT must be a multiple of this when > 0             */
    const char *choices;       /* ENUM: "a|b|c"; NULL otherwise                       */
    const char *unit;          /* "mm", "deg", "px", "" ...                           */
    const char *help;          /* one line                                            */
} binocle_param_desc;

typedef struct binocle_param {
    const char *name;
    int32_t type;      /* the desc's type                                             */
    int64_t i;         /* BOOL (0/1), INT                                             */
    double d;          /* DOUBLE                                                      */
    const char *s;     /* STRING, ENUM, PATH (absolute), YAML and *_LIST as YAML text */
    int32_t explicit_; /* 1 when set in the YAML / on the command line, 0 = default   */
} binocle_param;

/* ---- Services the host offers to every plugin ---------------------------------- */
enum { BINOCLE_LOG_DEBUG = 0, BINOCLE_LOG_INFO = 1, BINOCLE_LOG_WARNING = 2, BINOCLE_LOG_ERROR = 3 };

typedef struct binocle_host {
    uint32_t struct_size;
    void *context;
    /* Logs a line, tagged with the plugin's name by the host. */
    void (*log)(void *context, int32_t level, const char *message);
    /* Evaluators report figures here: name in snake_case with unit suffix where not SI
       ("bad_2px_percent"); unit is free text ("%", "mm", "px"). */
    void (*report_metric)(void *context, const char *name, double value, const char *unit);
    /* Free-form text result (JSON or YAML), e.g. a list of detected objects. */
    void (*report_text)(void *context, const char *name, const char *text);
} binocle_host;

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_COMMON_H */
