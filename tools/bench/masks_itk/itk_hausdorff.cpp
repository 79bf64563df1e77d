// ITK 5's HausdorffDistanceImageFilter on two NIfTI masks (non-zero voxels,
// UseImageSpacing on), the peer of rthdist-masks --convention itk.
//   itk-hausdorff A.nii B.nii [--runs N] [--threads T]
// Prints one JSON object: hd, average_hd (ITK's mean of the two directed
// means) and the median time of filter->Update() over N runs with the images
// already in memory (reading excluded).
#include <itkHausdorffDistanceImageFilter.h>
#include <itkImage.h>
#include <itkImageFileReader.h>
#include <itkMultiThreaderBase.h>

#include <algorithm>
#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <vector>

using Image = itk::Image<unsigned char, 3>;

int main(int argc, char** argv) {
    if (argc < 3) {
        std::fprintf(stderr, "usage: itk-hausdorff A.nii B.nii [--runs N] [--threads T]\n");
        return 2;
    }
    int runs = 3, threads = 0;
    for (int i = 3; i + 1 < argc; i += 2) {
        if (!std::strcmp(argv[i], "--runs")) runs = std::atoi(argv[i + 1]);
        if (!std::strcmp(argv[i], "--threads")) threads = std::atoi(argv[i + 1]);
    }
    if (threads > 0) itk::MultiThreaderBase::SetGlobalDefaultNumberOfThreads(threads);
    auto ra = itk::ImageFileReader<Image>::New();
    auto rb = itk::ImageFileReader<Image>::New();
    ra->SetFileName(argv[1]);
    rb->SetFileName(argv[2]);
    try {
        ra->Update();
        rb->Update();
    } catch (const itk::ExceptionObject& e) {
        std::fprintf(stderr, "itk-hausdorff: %s\n", e.what());
        return 3;
    }
    std::vector<double> ms;
    double hd = 0, avg = 0;
    for (int r = 0; r < runs; ++r) {
        auto f = itk::HausdorffDistanceImageFilter<Image, Image>::New();
        f->SetInput1(ra->GetOutput());
        f->SetInput2(rb->GetOutput());
        f->SetUseImageSpacing(true);
        const auto t0 = std::chrono::steady_clock::now();
        f->Update();
        ms.push_back(
            std::chrono::duration<double, std::milli>(std::chrono::steady_clock::now() - t0).count());
        hd = f->GetHausdorffDistance();
        avg = f->GetAverageHausdorffDistance();
    }
    std::sort(ms.begin(), ms.end());
    std::printf("{\"hd\": %.17g, \"average_hd\": %.17g, \"ms\": %.6f, \"runs\": %d, \"threads\": %u}\n", hd,
                avg, ms[ms.size() / 2], runs, itk::MultiThreaderBase::GetGlobalDefaultNumberOfThreads());
    return 0;
}
