// cvo_make_labels: a segmentation for every image of a folder by the colour rule of
// frontend/colour_class_labels.hpp (no learned model): the fixtures' labels, made at build time,
// for the runner's --segmentation and cvo_make_bag --segmentation.
#include <algorithm>
#include <array>
#include <filesystem>
#include <iomanip>
#include <iostream>
#include <vector>

#include <opencv2/imgcodecs.hpp>

#include "cvo_odometry/frontend/colour_class_labels.hpp"
#include "cvo_odometry/tools/command_line.hpp"

namespace {

const char* kUsage =
    "usage: cvo_make_labels --images DIR --out DIR\n"
    "  writes OUT/<name>.png (8-bit class ids 0-5: dark, grey, bright, red-yellow, green-cyan,\n"
    "  blue-magenta) for every .png/.jpg of DIR; use with --semantic-classes 6\n";

}  // namespace

int main(int argc, char** argv) {
  namespace fs = std::filesystem;
  try {
    const cvo::CommandLine cli(argc, argv, {"images", "out"}, {"help"});
    if (cli.has("help") || !cli.has("images")) {
      std::cout << kUsage;
      return cli.has("help") ? 0 : 2;
    }
    std::vector<fs::path> images;
    for (const auto& entry : fs::directory_iterator(cli.get("images"))) {
      const std::string ext = entry.path().extension().string();
      if (ext == ".png" || ext == ".jpg") images.push_back(entry.path());
    }
    if (images.empty()) throw std::runtime_error("no .png or .jpg in " + cli.get("images"));
    std::sort(images.begin(), images.end());
    const fs::path out = cli.require("out");
    fs::create_directories(out);
    std::array<double, cvo::kColourClassCount> share{};
    for (const fs::path& path : images) {
      const cv::Mat image = cv::imread(path.string(), cv::IMREAD_UNCHANGED);
      if (image.empty()) throw std::runtime_error("cannot read " + path.string());
      const cv::Mat labels = cvo::colourClassLabels(image);
      for (int k = 0; k < cvo::kColourClassCount; ++k)
        share[k] += cv::countNonZero(labels == k) / static_cast<double>(labels.total());
      const fs::path target = out / path.filename().replace_extension(".png");
      if (!cv::imwrite(target.string(), labels))
        throw std::runtime_error("cannot write " + target.string());
    }
    std::cout << "cvo_make_labels: " << images.size() << " images -> " << out.string()
              << "; pixels per class (%):";
    for (double s : share)
      std::cout << " " << std::fixed << std::setprecision(1) << 100.0 * s / images.size();
    std::cout << "\n";
    return 0;
  } catch (const std::exception& e) {
    std::cerr << "cvo_make_labels: " << e.what() << "\n";
    return 2;
  }
}
