/* SPDX-License-Identifier: MIT */
/* The plugin ABI compiled as C11 (-std=c11 -pedantic -Werror): the recorded layout is
 * checked at compile time, and handed to the C++ side of the test as the C compiler
 * measured it. */
#ifdef __cplusplus
#error "abi_layout_c11.c must be compiled as C"
#endif
#if !defined(__STDC_VERSION__) || __STDC_VERSION__ < 201112L
#error "abi_layout_c11.c must be compiled as C11 or later"
#endif

#include "abi_layout.h"

#include <binocle/abi.h>

#include <stddef.h>

#if BINOCLE_ABI_LAYOUT_RECORDED
#define ASSERT_SIZE(type, bytes) _Static_assert(sizeof(type) == (bytes), "sizeof(" #type ") is not the recorded " #bytes);
#define ASSERT_FIELD(type, member, offset) \
    _Static_assert(offsetof(type, member) == (offset), "offsetof(" #type ", " #member ") is not the recorded " #offset);
#define ASSERT_CONSTANT(name, value) _Static_assert((name) == (value), #name " is not the recorded " #value);
BINOCLE_ABI_LAYOUT(ASSERT_SIZE, ASSERT_FIELD, ASSERT_CONSTANT)
#endif

/* The header is frozen for every ABI version: a table of any kind starts with it. */
_Static_assert(offsetof(binocle_source_api, header) == 0, "a table must start with its header");
_Static_assert(offsetof(binocle_matcher_api, header) == 0, "a table must start with its header");
_Static_assert(offsetof(binocle_cloud_transform_api, header) == 0, "a table must start with its header");
_Static_assert(offsetof(binocle_evaluator_api, header) == 0, "a table must start with its header");

#define ENTRY_SIZE(type, bytes) {"sizeof(" #type ")", (long long)sizeof(type), (bytes)},
#define ENTRY_FIELD(type, member, offset) {"offsetof(" #type ", " #member ")", (long long)offsetof(type, member), (offset)},
#define ENTRY_CONSTANT(name, value) {#name, (long long)(name), (value)},

static const binocle_test_layout_entry entries[] = {BINOCLE_ABI_LAYOUT(ENTRY_SIZE, ENTRY_FIELD, ENTRY_CONSTANT)};

const binocle_test_layout_entry *binocle_test_c_layout(int *count) {
    *count = (int)(sizeof entries / sizeof entries[0]);
    return entries;
}
