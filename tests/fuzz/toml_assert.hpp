// Force-included (-include) before toml++ in the fuzz build, so that toml++'s own
// assertions stay on, with one class passed over: preconditions on the character under
// the cursor (`*cp`) of toml++ 3.3.0's parse_* functions. Debian's toml++ 3.3.0 reaches
// some on malformed input, e.g. "[[[id]" (marzer/tomlplusplus#301, fixed upstream after
// 3.3.0) or a date-time "1979-05-27T\x107:32:00Z"; each function then checks the
// character itself and reports a normal syntax error. That is what the release build
// does (the Debian shared library is built without assertions, and with GCC, where
// TOML_ASSUME is a no-op): `superball explore` prints "TOML syntax error" and exits 2.
// Any other toml++ assertion is a crash; AddressSanitizer still watches every access.
#pragma once

#include <cstdio>
#include <cstdlib>
#include <cstring>

inline void superball_fuzz_toml_assert_failed(const char* expr, const char* file, int line)
{
    if (std::strstr(expr, "*cp") != nullptr) return;  // re-checked by the parser: a syntax error follows
    std::fprintf(stderr, "%s:%d: toml++ assertion failed: %s\n", file, line, expr);
    std::abort();
}

#define TOML_ASSERT(expr) ((expr) ? void(0) : superball_fuzz_toml_assert_failed(#expr, __FILE__, __LINE__))
