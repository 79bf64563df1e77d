// An environment variable set (or, with value nullptr, unset) for a scope
// and restored after it, also when the scope is left early (an assertion, a
// GTEST_SKIP): for tests of the RTHDIST_* switches read at Engine creation.
#pragma once

#include <cstdlib>
#include <optional>
#include <string>

namespace rthdist::test {

class ScopedEnv {
public:
    ScopedEnv(const char* name, const char* value) : m_name(name) {
        const char* before = std::getenv(name);
        if (before) m_saved = before;
        if (value)
            setenv(name, value, 1);
        else
            unsetenv(name);
    }
    ~ScopedEnv() {
        if (m_saved)
            setenv(m_name, m_saved->c_str(), 1);
        else
            unsetenv(m_name);
    }
    ScopedEnv(const ScopedEnv&) = delete;
    ScopedEnv& operator=(const ScopedEnv&) = delete;

private:
    const char* m_name;
    std::optional<std::string> m_saved;
};

}  // namespace rthdist::test
