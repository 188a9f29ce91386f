/* SPDX-License-Identifier: MIT */
/* Binocle plugin ABI: the whole C interface in one include. */
#ifndef BINOCLE_ABI_H
#define BINOCLE_ABI_H

#include "abi/common.h"
#include "abi/source.h"
#include "abi/matcher.h"
#include "abi/cloud_transform.h"
#include "abi/evaluator.h"
#include "abi/init_error.h"

#endif /* BINOCLE_ABI_H */
