// HSR_EMBED(symbol, path): a file embedded into the binary at build time as a NUL-terminated char array
// `symbol` (assembler .incbin), for pages that must work offline (src/report/embed.cpp, src/tiles3d/embed.cpp).
// `path` is a string literal; HSR_STR turns a -D definition holding an absolute path into one.
#pragma once

#define HSR_STR2(x) #x
#define HSR_STR(x) HSR_STR2(x)

#define HSR_EMBED(symbol, path)                                   \
  __asm__(".section .rodata\n"                                    \
          ".global " #symbol "\n"                                 \
          ".type " #symbol ", @object\n"                          \
          ".balign 16\n" #symbol ":\n"                            \
          ".incbin \"" path "\"\n"                                \
          ".byte 0\n"                                             \
          ".size " #symbol ", . - " #symbol "\n"                  \
          ".previous\n")
