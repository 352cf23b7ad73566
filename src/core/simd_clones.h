// Private to the core: one function per instruction set from one inlined loop body, and the
// copy of the active path (simd_path.h). On x86-64 with GCC: AVX-512F, AVX2 and the baseline
// ("portable"); elsewhere (aarch64, whose baseline has NEON) only the baseline. Each body is
// `inline __attribute__((always_inline)) void <name>Body(...)` with `#pragma omp simd`
// (-fopenmp-simd makes GCC vectorise every copy at -O2).
#pragma once

#include "cube_scan_matcher/core/simd_path.h"

#if defined(__x86_64__) && defined(__GNUC__)
#define CSM_HAVE_X86_PATHS 1
#define CSM_X86_CLONES(name, params, args)                                          \
  __attribute__((target("avx2"))) void name##Avx2 params { name##Body args; }       \
  __attribute__((target("avx512f"))) void name##Avx512 params { name##Body args; }
/// The copy of `name` for `path` (a function pointer).
#define CSM_PICK_CLONE(name, path)                                                  \
  ((path) == SimdPath::Avx512 ? name##Avx512                                        \
                              : (path) == SimdPath::Avx2 ? name##Avx2 : name##Portable)
#else
#define CSM_X86_CLONES(name, params, args)
#define CSM_PICK_CLONE(name, path) ((void)(path), name##Portable)
#endif

/// Defines void name##Portable`params` (and on x86-64 name##Avx2, name##Avx512), each calling
/// name##Body`args`.
#define CSM_SIMD_CLONES(name, params, args)        \
  void name##Portable params { name##Body args; } \
  CSM_X86_CLONES(name, params, args)
