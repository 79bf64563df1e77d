// rthdist-prepared-bench: what a caller gains by preparing sets once
// (Engine::prepare) instead of one-shot calls, and what a batch of many
// small pairs costs per pair (issue 11's figures).
//
//   rthdist-prepared-bench pair A B [--translate T] [--name N]
//     one-shot compute(A, B) vs compute(prepared A, prepared B), median of
//     --runs calls after --warmup, both from the same Engine; the two H
//     must agree within the contract's tolerance.
//   rthdist-prepared-bench batch MODEL... [--pairs 400] [--min 2000] [--max 10000] [--seed 1]
//     --pairs pairs, each of two random subsets (sizes in [min, max], fixed
//     seed) of two of the models, prepared once; then computeBatch over all
//     pairs, --runs times; the median per pair is the batch wall / pairs.
// Prints one JSON object per run on stdout (medians in ms).
#include <CLI/CLI.hpp>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <iostream>
#include <random>
#include <string>
#include <vector>

#include "core/stopwatch.hpp"
#include "rthdist/io.hpp"
#include "rthdist/rthdist.hpp"

namespace {

using rthdist::HausdorffResult;
using rthdist::core::Clock;
using rthdist::core::msSince;

double median(std::vector<double> v) {
    std::sort(v.begin(), v.end());
    return v.empty() ? 0.0 : v[v.size() / 2];
}

struct Settings {
    std::string backend = "auto";
    int runs = 7;
    int warmup = 3;
};

rthdist::Result<rthdist::Engine> makeEngine(const Settings& s) {
    rthdist::EngineOptions o;
    if (!rthdist::parseBackend(s.backend, o.backend))
        return rthdist::Error{rthdist::ErrorCode::kInvalidArgument, "unknown backend " + s.backend};
    return rthdist::Engine::create(o);
}

std::vector<glm::vec3> loadFloats(const std::string& path) {
    auto p = rthdist::io::loadPoints(path);
    if (!p) throw std::runtime_error(p.error().message);
    return std::move(p.value());
}

// Medians of a result series: wall of the call, and the device's stages.
nlohmann::ordered_json stageMedians(const std::vector<double>& wall, const std::vector<HausdorffResult>& rs) {
    auto of = [&](double rthdist::Timings::*field) {
        std::vector<double> v;
        for (const HausdorffResult& r : rs) v.push_back(r.timings.*field);
        return median(v);
    };
    std::vector<double> gpu, gpuAll;
    for (const HausdorffResult& r : rs) {
        gpu.push_back(r.timings.gpuIndex + r.timings.gpuCull + r.timings.gpuSearch + r.timings.gpuRefine);
        gpuAll.push_back(gpu.back() + r.timings.gpuUpload);
    }
    return {{"wall", median(wall)},
            {"upload", of(&rthdist::Timings::upload)},
            {"index", of(&rthdist::Timings::index)},
            {"cull", of(&rthdist::Timings::cull)},
            {"search", of(&rthdist::Timings::search)},
            {"refine", of(&rthdist::Timings::refine)},
            {"check", of(&rthdist::Timings::check)},
            {"gpu_sum", median(gpu)},
            {"gpu_upload", of(&rthdist::Timings::gpuUpload)},  // device time of the transfers
            {"gpu_with_upload", median(gpuAll)},               // every device stage, transfers included
            {"wall_over_gpu", median(wall) / median(gpuAll)}};
}

template <class Call>
nlohmann::ordered_json timeCalls(const Settings& s, Call&& call, double& h) {
    std::vector<double> wall;
    std::vector<HausdorffResult> results;
    for (int i = 0; i < s.warmup + s.runs; ++i) {
        const auto t0 = Clock::now();
        rthdist::Result<HausdorffResult> r = call();
        const double ms = msSince(t0);
        if (!r) throw std::runtime_error(r.error().message);
        h = r->hausdorff;
        if (i < s.warmup) continue;
        wall.push_back(ms);
        results.push_back(std::move(r.value()));
    }
    return stageMedians(wall, results);
}

int runPair(const Settings& s, const std::string& pathA, const std::string& pathB, double translate,
            const std::string& name) {
    std::vector<glm::vec3> a = loadFloats(pathA), b = loadFloats(pathB);
    if (translate != 0.0) {
        float lo = a[0].x, hi = a[0].x;
        for (const glm::vec3& p : a) lo = std::min(lo, p.x), hi = std::max(hi, p.x);
        for (glm::vec3& p : b) p.x += float(translate * double(hi - lo));
    }
    const auto created = Clock::now();
    auto engine = makeEngine(s);
    if (!engine) throw std::runtime_error(engine.error().message);
    const double createMs = msSince(created);
    double hOnce = 0.0, hPrepared = 0.0;
    auto once = timeCalls(
        s, [&] { return engine->compute(a, b, rthdist::CallOptions{}); }, hOnce);
    auto t0 = Clock::now();
    auto pa = engine->prepare(a);
    auto pb = engine->prepare(b);
    const double prepareMs = msSince(t0);
    if (!pa || !pb) throw std::runtime_error(pa ? pb.error().message : pa.error().message);
    auto prepared = timeCalls(
        s, [&] { return engine->compute(*pa, *pb); }, hPrepared);
    nlohmann::ordered_json out{{"name", name},
                               {"backend", rthdist::backendName(engine->backend())},
                               {"device", engine->deviceName()},
                               {"engine_create_ms", createMs},
                               {"pipeline_cache", engine->pipelineCacheStatus()},
                               {"points", {a.size(), b.size()}},
                               {"h_one_shot", hOnce},
                               {"h_prepared", hPrepared},
                               {"prepare_both_ms", prepareMs},
                               {"prepared_device_bytes", pa->deviceBytes() + pb->deviceBytes()},
                               {"one_shot_ms", once},
                               {"prepared_ms", prepared}};
    std::cout << out.dump() << "\n";
    return std::abs(hOnce - hPrepared) <= 1e-6 * std::max(1.0, hOnce) ? 0 : 1;
}

// Pairs of random subsets of the models (fixed seed).
int runBatch(const Settings& s, const std::vector<std::string>& models, int pairs, int minPoints,
             int maxPoints, uint64_t seed) {
    std::vector<std::vector<glm::vec3>> clouds;
    for (const std::string& m : models) clouds.push_back(loadFloats(m));
    std::mt19937_64 rng(seed);
    std::vector<std::vector<glm::vec3>> subsets;
    for (int i = 0; i < 2 * pairs; ++i) {
        const auto& cloud = clouds[rng() % clouds.size()];
        const size_t n =
            std::min(cloud.size(), size_t(minPoints + int(rng() % uint64_t(maxPoints - minPoints + 1))));
        std::vector<glm::vec3> subset(n);
        for (glm::vec3& p : subset) p = cloud[rng() % cloud.size()];
        subsets.push_back(std::move(subset));
    }
    auto engine = makeEngine(s);
    if (!engine) throw std::runtime_error(engine.error().message);
    auto t0 = Clock::now();
    std::vector<rthdist::PreparedSet> sets;
    for (const auto& subset : subsets) {
        auto p = engine->prepare(subset);
        if (!p) throw std::runtime_error(p.error().message);
        sets.push_back(*p);
    }
    const double prepareMs = msSince(t0);
    std::vector<rthdist::PairRef> refs;
    for (int i = 0; i < pairs; ++i) refs.push_back({size_t(2 * i), size_t(2 * i + 1)});
    std::vector<double> perPair, callMedians;
    for (int run = 0; run < s.warmup + s.runs; ++run) {
        t0 = Clock::now();
        auto results = engine->computeBatch(sets, refs);
        const double ms = msSince(t0);
        std::vector<double> totals;
        for (const auto& r : results) {
            if (!r) throw std::runtime_error(r.error().message);
            totals.push_back(r->timings.total);
        }
        if (run < s.warmup) continue;
        perPair.push_back(ms / pairs);
        callMedians.push_back(median(totals));
    }
    // One pair per call, as a caller without batches does (the median over
    // the pairs of one call's wall time): one-shot from the arrays, and on
    // the prepared sets.
    std::vector<double> oneShot, preparedCall;
    for (int i = 0; i < pairs; ++i) {
        auto t1 = Clock::now();
        auto r = engine->compute(subsets[size_t(2 * i)], subsets[size_t(2 * i + 1)], rthdist::CallOptions{});
        oneShot.push_back(msSince(t1));
        t1 = Clock::now();
        auto p = engine->compute(sets[size_t(2 * i)], sets[size_t(2 * i + 1)]);
        preparedCall.push_back(msSince(t1));
        if (!r || !p) throw std::runtime_error(!r ? r.error().message : p.error().message);
        if (r->hausdorff != p->hausdorff) throw std::runtime_error("one-shot and prepared H differ");
    }
    // Spot check of exactness: a few pairs one-shot on the CPU backend.
    auto cpu = rthdist::Engine::create(rthdist::EngineOptions{rthdist::Backend::kCpu});
    auto results = engine->computeBatch(sets, refs);
    double maxDiff = 0.0;
    for (int i = 0; i < pairs; i += std::max(1, pairs / 20)) {
        auto ref = cpu->compute(subsets[size_t(2 * i)], subsets[size_t(2 * i + 1)], rthdist::CallOptions{});
        maxDiff = std::max(maxDiff, std::abs(ref->hausdorff - results[size_t(i)]->hausdorff));
    }
    nlohmann::ordered_json out{{"name", "batch"},
                               {"backend", rthdist::backendName(engine->backend())},
                               {"device", engine->deviceName()},
                               {"pairs", pairs},
                               {"points_per_set", {minPoints, maxPoints}},
                               {"prepare_all_ms", prepareMs},
                               {"batch_per_pair_ms", median(perPair)},
                               {"call_total_median_ms", median(callMedians)},
                               {"one_shot_call_median_ms", median(oneShot)},
                               {"prepared_call_median_ms", median(preparedCall)},
                               {"cpu_check_max_abs_diff", maxDiff}};
    std::cout << out.dump() << "\n";
    return maxDiff <= 1e-6 ? 0 : 1;
}

}  // namespace

int main(int argc, char** argv) {
    CLI::App app{"rthdist-prepared-bench: prepared sets and batches against one-shot calls"};
    Settings s;
    app.add_option("--backend", s.backend, "auto, ray-query, rt-pipeline or cpu");
    app.add_option("--runs", s.runs, "timed calls")->check(CLI::PositiveNumber);
    app.add_option("--warmup", s.warmup, "untimed calls first")->check(CLI::NonNegativeNumber);
    app.require_subcommand(1);
    std::string a, b, name = "pair";
    double translate = 0.0;
    CLI::App* pair = app.add_subcommand("pair", "one-shot vs prepared on one pair");
    pair->add_option("A", a)->required();
    pair->add_option("B", b)->required();
    pair->add_option("--translate", translate, "shift B along x by this fraction of A's x extent");
    pair->add_option("--name", name);
    std::vector<std::string> models;
    int pairs = 400, minPoints = 2000, maxPoints = 10000;
    uint64_t seed = 1;
    CLI::App* batch = app.add_subcommand("batch", "many small pairs in one computeBatch");
    batch->add_option("MODELS", models)->required();
    batch->add_option("--pairs", pairs)->check(CLI::PositiveNumber);
    batch->add_option("--min", minPoints)->check(CLI::PositiveNumber);
    batch->add_option("--max", maxPoints)->check(CLI::PositiveNumber);
    batch->add_option("--seed", seed);
    CLI11_PARSE(app, argc, argv);
    try {
        if (maxPoints < minPoints) throw std::runtime_error("--max must be >= --min");
        return pair->parsed() ? runPair(s, a, b, translate, name)
                              : runBatch(s, models, pairs, minPoints, maxPoints, seed);
    } catch (const std::exception& e) {
        std::fprintf(stderr, "rthdist-prepared-bench: %s\n", e.what());
        return 1;
    }
}
