// Plane: the storage of one full-screen plane (a G-buffer channel, the visibility buffer), a
// std::vector whose allocator staggers where each plane starts within a 4 KiB page.
//
// Why: planes of a frame are large, so the C library maps each one fresh from the kernel and
// they all start at the same offset within a page. A loop that touches pixel i of nine planes
// (the G-buffer resolve writes normal, albedo and specular channels and reads the visibility
// buffer) then hits one L1 cache set nine times, more than it has ways, and its loads alias the
// stores' page offsets. Measured on one core of the 2-core test machine, writing 8 float planes
// of 1280x720: 10.2-11.8 ms page-aligned, 4.5-6.1 ms with the starts 64 bytes apart.
// Staggering changes addresses only, never a value.
#pragma once

#include <atomic>
#include <cstddef>
#include <cstdint>
#include <new>
#include <vector>

namespace gbuffer {

template <class T> struct StaggeredAllocator {
    using value_type = T;
    // Start offsets cycle through kSlots cache lines; kSlots * kLine stays under a page.
    static constexpr size_t kLine = 64;
    static constexpr size_t kSlots = 61;

    StaggeredAllocator() = default;
    template <class U> StaggeredAllocator(const StaggeredAllocator<U>&) {}

    T* allocate(size_t count) {
        if (count > (SIZE_MAX - kLine * (kSlots + 1)) / sizeof(T))
            throw std::bad_array_new_length();
        static std::atomic<uint32_t> nextSlot{0};
        const size_t slot = nextSlot.fetch_add(1, std::memory_order_relaxed) % kSlots;
        // One line before the data holds the block's start, for deallocate.
        const size_t offset = kLine * (slot + 1);
        auto* block = static_cast<std::byte*>(
            ::operator new(count * sizeof(T) + offset, std::align_val_t(kLine)));
        std::byte* data = block + offset;
        reinterpret_cast<std::byte**>(data)[-1] = block;
        return reinterpret_cast<T*>(data);
    }
    void deallocate(T* data, size_t) noexcept {
        std::byte* block = reinterpret_cast<std::byte**>(data)[-1];
        ::operator delete(block, std::align_val_t(kLine));
    }

    template <class U> bool operator==(const StaggeredAllocator<U>&) const { return true; }
};

template <class T> using Plane = std::vector<T, StaggeredAllocator<T>>;

} // namespace gbuffer
