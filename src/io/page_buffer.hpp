// Storage for write buffers: uninitialised, since every byte is written before it is read,
// and in transparent huge pages where Linux gives them on request (madvise mode, Debian's
// default). The first fill of a rank's two tile buffers (12 MiB each for 16-bit counts)
// took 6000 page faults and zeroed each page twice (std::vector::resize, then the
// kernel): about 5 % of the compute phase of a 4096^2 slice at -n 1. With 2 MiB pages it
// takes a dozen faults. (Written here because no Debian library offers an allocator for
// this: std::vector zero-fills, and a huge-page request needs madvise on aligned memory.)
#pragma once

#include <cstddef>
#include <cstdlib>
#include <memory>
#include <type_traits>

namespace superball {

// At least `bytes`, aligned to a huge page when at least one, asked for as huge pages;
// std::bad_alloc if there is no room. Freed with std::free.
void* allocate_pages(std::size_t bytes);

template <class T>
class PageArray {
    static_assert(std::is_trivially_copyable_v<T> && std::is_trivially_default_constructible_v<T>);

public:
    // Room for n values, uninitialised: allocated at the first call and kept, replaced by
    // a larger one (contents lost) when n grows.
    T* reserve(std::size_t n)
    {
        if (n > size_) {
            p_.reset(static_cast<T*>(allocate_pages(n * sizeof(T))));
            size_ = n;
        }
        return p_.get();
    }
    const T* data() const { return p_.get(); }

private:
    struct Free {
        void operator()(T* p) const noexcept { std::free(p); }
    };
    std::unique_ptr<T, Free> p_;
    std::size_t size_ = 0;
};

}  // namespace superball
