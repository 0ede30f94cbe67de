#include "page_buffer.hpp"

#include <new>

#if __has_include(<sys/mman.h>)
#include <sys/mman.h>
#endif

namespace superball {

void* allocate_pages(std::size_t bytes)
{
    // 2 MiB: the huge page of x86-64 and of arm64 with 4 KiB pages. Elsewhere the request
    // below is refused or means something smaller; the memory is the same either way.
    constexpr std::size_t huge = std::size_t{2} << 20;
    const bool large = bytes >= huge;
    const std::size_t align = large ? huge : 64;
    const std::size_t size = (bytes + align - 1) / align * align;  // aligned_alloc wants a multiple
    void* const p = std::aligned_alloc(align, size == 0 ? align : size);
    if (p == nullptr) throw std::bad_alloc();
#ifdef MADV_HUGEPAGE
    // A request: where huge pages are off (or the kernel refuses), plain pages as before.
    if (large) (void)madvise(p, size, MADV_HUGEPAGE);
#endif
    return p;
}

}  // namespace superball
