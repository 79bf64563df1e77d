// The names of the backends (options.hpp): the words of the CLI, the JSON
// and the messages, shared by every layer.
#include <string>

#include "rthdist/options.hpp"

namespace rthdist {

const char* backendName(Backend backend) {
    switch (backend) {
        case Backend::kAuto: return "auto";
        case Backend::kRayQuery: return "ray-query";
        case Backend::kRtPipeline: return "rt-pipeline";
        case Backend::kCpu: return "cpu";
    }
    return "?";
}

bool parseBackend(const std::string& text, Backend& out) {
    for (Backend b : {Backend::kAuto, Backend::kRayQuery, Backend::kRtPipeline, Backend::kCpu}) {
        if (text == backendName(b)) {
            out = b;
            return true;
        }
    }
    return false;
}

}  // namespace rthdist
