// A Vulkan structure with its sType (and pNext) set and every other member
// zero: what `VkFoo foo{VK_STRUCTURE_TYPE_FOO};` means, written so that no
// member is left to an aggregate's missing initializer (GCC's
// -Wmissing-field-initializers names each one). Header only: the other
// layers, the tools and the tests that fill Vulkan structures use it too.
#pragma once

#include <vulkan/vulkan.h>

namespace rthdist::gpu {

template <class T>
[[nodiscard]] constexpr T vkStruct(VkStructureType type) {
    T s{};
    s.sType = type;
    return s;
}

// The same, chained in front of `next` (a structure the call also fills or reads).
template <class T, class Next>
[[nodiscard]] constexpr T vkStruct(VkStructureType type, Next* next) {
    T s{};
    s.sType = type;
    s.pNext = next;
    return s;
}

}  // namespace rthdist::gpu
