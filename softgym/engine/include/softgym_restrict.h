/* softgym: the restrict qualifier of the kernel's pointers, spelt for each compiler.

   A vectorised pass's inputs and outputs never alias; saying so lets the compiler
   vectorise it. GCC and Clang spell it __restrict__, MSVC __restrict; another compiler
   gets none (the same results, perhaps slower). The kernel's headers and the restrict
   pointer types of _batch.pxd use SOFTGYM_RESTRICT, never a compiler's own spelling. */
#ifndef SOFTGYM_RESTRICT_H
#define SOFTGYM_RESTRICT_H

#if defined(__GNUC__) || defined(__clang__)
#define SOFTGYM_RESTRICT __restrict__
#elif defined(_MSC_VER)
#define SOFTGYM_RESTRICT __restrict
#else
#define SOFTGYM_RESTRICT
#endif

#endif /* SOFTGYM_RESTRICT_H */
