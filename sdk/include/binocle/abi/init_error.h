/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: the optional symbol that says why the init symbol returned NULL.
 *
 * A plugin that cannot give a table (a Python plugin whose module does not parse, a
 * plugin whose data file is missing) returns NULL from binocle_plugin_init; the host
 * then refuses the file. Without this symbol the refusal can only say that there was no
 * table; with it, the host adds the plugin's reason to the refusal that the user sees
 * (`binocle plugins`, a rig naming the plugin, the Python module's error). Adding it
 * changes no table: the ABI and API versions stay. */
#ifndef BINOCLE_ABI_INIT_ERROR_H
#define BINOCLE_ABI_INIT_ERROR_H

#ifdef __cplusplus
extern "C" {
#endif

/* Exported as "binocle_plugin_init_error" (optional). */
#define BINOCLE_PLUGIN_INIT_ERROR_SYMBOL "binocle_plugin_init_error"

/* After binocle_plugin_init returned NULL: why (the file, the line, what went wrong),
 * UTF-8, valid while the library is loaded; NULL when it has nothing to say. */
typedef const char *(*binocle_plugin_init_error_fn)(void);

#ifdef __cplusplus
}
#endif

#endif /* BINOCLE_ABI_INIT_ERROR_H */
