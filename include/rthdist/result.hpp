// rthdist — expected failures as values.
//
// Every public entry point returns Result<T>: either a value or an Error with
// a code and a message that names the file, the element and the place (line,
// vertex, byte offset) or the device feature at fault. The library never
// throws across its boundary and never calls exit() or abort(). Result reads
// like std::optional/std::expected (has_value, value, value_or, ->, *);
// ok() and the bool conversion stay for earlier callers. What a process does
// with an error (the CLI's exit codes) is the caller's business.
#pragma once

#include <string>
#include <utility>
#include <variant>
#include <vector>

namespace rthdist {

enum class ErrorCode {
    kInvalidArgument,  // bad options or an empty point set (H is undefined)
    kBadInput,         // unreadable or malformed input file, NaN/Inf coordinate
    kNoDevice,         // no Vulkan device offers what the chosen backend needs
    kOutOfMemory,      // inputs do not fit the device or host memory
    kInternal,         // a Vulkan call failed or an invariant broke
    kCancelled,        // CallOptions::cancel was set during the call
};

struct Error {
    ErrorCode code = ErrorCode::kInternal;
    std::string message;  // what failed, naming the file, element or feature
    // Optional detailed reasons behind the message, one per entry (e.g. why
    // each candidate was rejected); empty when the message says it all.
    std::vector<std::string> details;
    // The VkResult of the Vulkan call that failed (a negative VK_ERROR_*), 0
    // when the error did not come from a Vulkan call. An int, so that this
    // header needs no Vulkan include.
    int vkResult = 0;

    Error() = default;
    // Error{code, message}; the reasons and the VkResult where known. (A
    // constructor rather than an aggregate, so that Error{code, message}
    // leaves the new members defaulted without -Wmissing-field-initializers.)
    Error(ErrorCode errorCode, std::string text, std::vector<std::string> reasons = {}, int vkError = 0)
        : code(errorCode), message(std::move(text)), details(std::move(reasons)), vkResult(vkError) {}
};

template <class T>
class [[nodiscard]] Result {
public:
    Result(T value) : m_v(std::in_place_index<0>, std::move(value)) {}
    Result(Error error) : m_v(std::in_place_index<1>, std::move(error)) {}

    [[nodiscard]] bool has_value() const { return m_v.index() == 0; }
    [[nodiscard]] bool ok() const { return has_value(); }
    explicit operator bool() const { return has_value(); }

    T& value() & { return std::get<0>(m_v); }
    const T& value() const& { return std::get<0>(m_v); }
    T&& value() && { return std::get<0>(std::move(m_v)); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }

    // The value, or `fallback` when this holds an error.
    template <class U>
    [[nodiscard]] T value_or(U&& fallback) const& {
        return has_value() ? value() : static_cast<T>(std::forward<U>(fallback));
    }
    template <class U>
    [[nodiscard]] T value_or(U&& fallback) && {
        return has_value() ? std::move(value()) : static_cast<T>(std::forward<U>(fallback));
    }

    const Error& error() const { return std::get<1>(m_v); }

private:
    std::variant<T, Error> m_v;
};

}  // namespace rthdist
