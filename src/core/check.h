#pragma once
// Invariant checks (docs/style.md §8, tier 2). A failed CHECK is a bug in lamina, not bad input: it
// prints where and aborts. Bad input is rejected earlier, at parse time, with lamina::InputError.

#include <cstdio>
#include <cstdlib>

#define LAMINA_CHECK(cond)                                                                 \
    do {                                                                                   \
        if (!(cond)) {                                                                     \
            std::fprintf(stderr, "lamina: internal check failed at %s:%d: %s\n", __FILE__, \
                         __LINE__, #cond);                                                 \
            std::abort();                                                                  \
        }                                                                                  \
    } while (false)

#ifdef NDEBUG
#define LAMINA_DCHECK(cond) \
    do {                    \
    } while (false)
#else
#define LAMINA_DCHECK(cond) LAMINA_CHECK(cond)
#endif
