// rthdist — expected failures as values.
//
// Every public entry point returns Result<T>: either a value or an Error with
// a code and a message that names the file, the element and the place (line,
// vertex, byte offset) or the device feature at fault. The library never
// throws across its boundary and never calls exit() or abort().
#pragma once

#include <string>
#include <utility>
#include <variant>

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
    std::string message;
};

// Process exit codes used by the CLI for each error code.
[[nodiscard]] constexpr int exitCodeFor(ErrorCode code) {
    switch (code) {
        case ErrorCode::kInvalidArgument: return 3;
        case ErrorCode::kBadInput: return 3;
        case ErrorCode::kNoDevice: return 4;
        case ErrorCode::kOutOfMemory: return 1;
        case ErrorCode::kInternal: return 1;
        case ErrorCode::kCancelled: return 130;
    }
    return 1;
}

template <class T>
class [[nodiscard]] Result {
public:
    Result(T value) : m_v(std::in_place_index<0>, std::move(value)) {}
    Result(Error error) : m_v(std::in_place_index<1>, std::move(error)) {}

    [[nodiscard]] bool ok() const { return m_v.index() == 0; }
    explicit operator bool() const { return ok(); }

    T& value() & { return std::get<0>(m_v); }
    const T& value() const& { return std::get<0>(m_v); }
    T&& value() && { return std::get<0>(std::move(m_v)); }
    T* operator->() { return &value(); }
    const T* operator->() const { return &value(); }
    T& operator*() & { return value(); }
    const T& operator*() const& { return value(); }

    const Error& error() const { return std::get<1>(m_v); }

private:
    std::variant<T, Error> m_v;
};

}  // namespace rthdist
