// rthdist-bench: times one case on one backend the way the benchmark notes
// report it: W warm-up calls, then N timed calls on the same Engine; prints
// one JSON object with the median of every stage (host wall clock and device
// timestamps), the end-to-end wall time of the call, and the CPU backend's
// value for agreement. Not a test: no thresholds.
//
//   rthdist-bench A B [--backend X] [--runs N] [--warmup W] [--translate F]
//                     [--bits K] [--name NAME] [--no-verify] [--per-point] [--growth G] [--budget S]
// --translate F moves B along x by F times B's x-extent (the paper's
// translation scenario without writing a copy to disk).
// --budget S (seconds; for slow devices such as lavapipe): warm-up calls stop
// once they have taken S/2 in all, timed calls once the next one would take
// the timed calls past S (at least one timed call); "runs" and "warmup" in the
// output are the counts actually made. The output also has the process's
// peak resident set size (max_rss_kb: inputs, index, device buffers).
#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <functional>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include <sys/resource.h>

#include "cli/command_line.hpp"
#include "cli/exit_codes.hpp"
#include "cli/json_output.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"

using namespace rthdist;

namespace {

double median(std::vector<double> v) {
    if (v.empty()) return 0.0;
    std::sort(v.begin(), v.end());
    size_t n = v.size();
    return n % 2 ? v[n / 2] : 0.5 * (v[n / 2 - 1] + v[n / 2]);
}

int usage() {
    std::fprintf(
        stderr,
        "usage: rthdist-bench A B [--backend auto|ray-query|rt-pipeline|cpu] [--runs N] [--warmup W]\n"
        "                     [--translate F] [--bits K] [--name NAME] [--no-verify] [--per-point] [--growth "
        "G]\n");
    return cli::kExitUsage;
}

struct BenchArgs {
    std::vector<std::string> files;
    Options options;
    int runs = 5, warmup = 2;
    double translate = 0.0, budgetS = 0.0;
    bool verify = true;
    std::string name;
};

// Numbers are read with atoi/atof as they always were; any error is the usage
// text (exit 2), whatever it is.
std::optional<BenchArgs> parseArgs(std::span<const std::string> argv) {
    BenchArgs out;
    cli::CommandLine line([&out](const std::string& token, bool) {
        if (!token.empty() && token[0] == '-') throw cli::UsageError{};  // "-", "--" and unknown options
        out.files.push_back(token);
    });
    auto value = [&line](const char* name, std::function<bool(const char*)> apply) {
        line.option(name, 1, [apply = std::move(apply)](const std::vector<std::string>& v, bool inlineValue) {
            if (inlineValue || v.empty() || !apply(v[0].c_str())) throw cli::UsageError{};
        });
    };
    value("--backend", [&out](const char* v) { return parseBackend(v, out.options.backend); });
    value("--runs", [&out](const char* v) { return (out.runs = std::atoi(v)) >= 1; });
    value("--warmup", [&out](const char* v) { return (out.warmup = std::atoi(v)) >= 0; });
    value("--translate", [&out](const char* v) {
        out.translate = std::atof(v);
        return true;
    });
    value("--bits", [&out](const char* v) {
        out.options.bits = std::atoi(v);
        return true;
    });
    value("--name", [&out](const char* v) {
        out.name = v;
        return true;
    });
    value("--budget", [&out](const char* v) { return (out.budgetS = std::atof(v)) > 0.0; });
    value("--growth", [&out](const char* v) {
        out.options.radiusGrowth = float(std::atof(v));
        return true;
    });
    line.flag("--per-point", [&out](bool withValue) {
        if (withValue) throw cli::UsageError{};
        out.options.perPointDistances = true;
    });
    line.flag("--no-verify", [&out](bool withValue) {
        if (withValue) throw cli::UsageError{};
        out.verify = false;
    });
    if (line.parse(argv) || out.files.size() != 2) return std::nullopt;
    return out;
}

}  // namespace

int main(int argc, char** argv) {
    const std::vector<std::string> list(argv + (argc > 0 ? 1 : 0), argv + argc);
    const std::optional<BenchArgs> parsed = parseArgs(list);
    if (!parsed) return usage();
    const BenchArgs& args = *parsed;
    const std::vector<std::string>& files = args.files;
    Options options = args.options;
    const int runs = args.runs, warmup = args.warmup;
    const double translate = args.translate, budgetS = args.budgetS;
    const bool verify = args.verify;
    const std::string& name = args.name;
    auto t0 = std::chrono::steady_clock::now();
    auto pa = io::loadPoints(files[0]);
    if (!pa)
        return std::fprintf(stderr, "rthdist-bench: %s\n", pa.error().message.c_str()), cli::kExitBadInput;
    auto pb = io::loadPoints(files[1]);
    if (!pb)
        return std::fprintf(stderr, "rthdist-bench: %s\n", pb.error().message.c_str()), cli::kExitBadInput;
    const double loadMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();
    std::vector<glm::vec3>& a = pa.value();
    std::vector<glm::vec3>& b = pb.value();
    if (translate != 0.0) {
        float lo = b[0].x, hi = b[0].x;
        for (const auto& p : b) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
        const float dx = float(translate * (double(hi) - double(lo)));
        for (auto& p : b) p.x += dx;
    }

    t0 = std::chrono::steady_clock::now();
    auto engine = Engine::create(options);
    if (!engine)
        return std::fprintf(stderr, "rthdist-bench: %s\n", engine.error().message.c_str()),
               cli::exitCodeFor(engine.error().code);
    const double setupMs =
        std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count();

    std::vector<double> wall, total, index, cull, search, refine, check, gIndex, gCull, gSearch, gRefine,
        gCert, cert, upload, pieces;
    HausdorffResult last;
    const double budgetMs = budgetS * 1e3;
    double warmMs = 0.0, timedMs = 0.0;
    int warmDone = 0;
    for (int r = 0; r < warmup + runs; ++r) {
        if (budgetMs > 0.0 && r < warmup && warmMs >= 0.5 * budgetMs) r = warmup;  // skip the other warm-ups
        if (budgetMs > 0.0 && r > warmup && timedMs + wall.back() > budgetMs) break;
        auto c0 = std::chrono::steady_clock::now();
        auto res = engine->compute(a, b);
        const double w =
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - c0).count();
        if (!res)
            return std::fprintf(stderr, "rthdist-bench: %s\n", res.error().message.c_str()),
                   cli::exitCodeFor(res.error().code);
        if (r < warmup) {
            warmMs += w;
            ++warmDone;
            continue;
        }
        const Timings& t = res->timings;
        timedMs += w;
        wall.push_back(w);
        total.push_back(t.total);
        upload.push_back(t.upload);
        index.push_back(t.index);
        cull.push_back(t.cull);
        search.push_back(t.search);
        refine.push_back(t.refine);
        check.push_back(t.check);
        gIndex.push_back(t.gpuIndex);
        gCull.push_back(t.gpuCull);
        gSearch.push_back(t.gpuSearch);
        gRefine.push_back(t.gpuRefine);
        gCert.push_back(t.gpuCertificate);
        cert.push_back(t.certificate);
        pieces.push_back(t.pieces);
        last = std::move(res.value());
    }

    bool agree = true;
    double cpuH = -1.0, cpuMs = 0.0;
    if (verify) {
        Options co;
        co.backend = Backend::kCpu;
        auto c0 = std::chrono::steady_clock::now();
        auto ref = hausdorff(a, b, co);
        cpuMs = std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - c0).count();
        if (!ref)
            return std::fprintf(stderr, "rthdist-bench: cpu: %s\n", ref.error().message.c_str()),
                   cli::kExitInternal;
        cpuH = ref->hausdorff;
        agree = std::abs(ref->aToB.distance - last.aToB.distance) <=
                    1e-6 * std::max(1e-30, ref->hausdorff) + 1e-9 &&
                std::abs(ref->bToA.distance - last.bToA.distance) <=
                    1e-6 * std::max(1e-30, ref->hausdorff) + 1e-9;
    }

    cli::Json counters = cli::Json::array();
    for (const Directed* d : {&last.aToB, &last.bToA}) {
        const Counters& c = d->counters;
        counters.push_back({{"queries", c.queries},
                            {"surviving", c.survivingQueries},
                            {"iterations", c.iterations},
                            {"rays", c.rays},
                            {"pairs", c.candidatePairs},
                            {"cells", c.occupiedCells}});
    }
    struct rusage ru {};
    getrusage(RUSAGE_SELF, &ru);
    const cli::Json j = {
        {"case", name.empty() ? files[0] + " vs " + files[1] : name},
        {"points", {{"a", a.size()}, {"b", b.size()}}},
        {"backend", backendName(last.backend)},
        {"per_point", options.perPointDistances},
        {"growth", double(options.radiusGrowth)},
        {"device", last.device},
        {"runs", int(wall.size())},
        {"warmup", warmDone},
        {"hausdorff", last.hausdorff},
        {"h_ab", last.aToB.distance},
        {"h_ba", last.bToA.distance},
        {"bits", {last.aToB.counters.bits, last.bToA.counters.bits}},
        {"load_ms", loadMs},
        {"setup_ms", setupMs},
        {"median_ms",
         {{"wall", median(wall)},
          {"total", median(total)},
          {"upload", median(upload)},
          {"index", median(index)},
          {"cull", median(cull)},
          {"search", median(search)},
          {"refine", median(refine)},
          {"check", median(check)},
          {"gpu_index", median(gIndex)},
          {"gpu_cull", median(gCull)},
          {"gpu_search", median(gSearch)},
          {"gpu_refine", median(gRefine)},
          {"certificate", median(cert)},
          {"pieces", median(pieces)},
          {"gpu_certificate", median(gCert)},
          {"gpu_sum", median(gIndex) + median(gCull) + median(gSearch) + median(gRefine) + median(gCert)}}},
        {"wall_ms_all", wall},
        {"counters", std::move(counters)},
        {"max_rss_kb", int64_t(ru.ru_maxrss)},
        {"cpu_hausdorff", cpuH},
        {"cpu_ms", cpuMs},
        {"agree", agree}};
    std::printf("%s\n", cli::jsonText(j, cli::JsonLayout::kCompact).c_str());
    return agree ? cli::kExitOk : cli::kExitInternal;
}
