// Trains an ORB vocabulary for the ORB-SLAM2 peer with ORB-SLAM2's own bundled DBoW2 and its own
// ORBextractor (the published ORBvoc.txt is not available). Out of tree; built by
// scripts/peers/build_orbslam2.sh. Not part of planeloc.
//
//   train_vocabulary K L IMAGE_LIST OUT_TXT
//
// IMAGE_LIST: one image path per line (colour images are read as grey). Every image gives the
// descriptors of ORBextractor(2000 features, 1.2 scale, 8 levels, FAST 20/7): the settings
// the benchmark tracks with. The vocabulary is DBoW2's TemplatedVocabulary<FORB::TDescriptor,
// FORB> with TF-IDF weighting and L1 scoring (what ORB-SLAM2 loads), k-means++ seeded with a
// fixed seed so that the same images give the same vocabulary. Written with saveToTextFile
// to OUT_TXT.tmp, then renamed to OUT_TXT.

#include <chrono>
#include <cstdio>
#include <cstdlib>
#include <fstream>
#include <iostream>
#include <opencv2/core/core.hpp>
#include <opencv2/imgcodecs.hpp>
#include <string>
#include <vector>

#include "DBoW2/FORB.h"
#include "DBoW2/TemplatedVocabulary.h"
#include "DUtils/Random.h"
#include "ORBextractor.h"

int main(int argc, char** argv) {
  if (argc != 5) {
    std::cerr << "usage: train_vocabulary K L IMAGE_LIST OUT_TXT\n";
    return 2;
  }
  const int k = std::atoi(argv[1]);
  const int levels = std::atoi(argv[2]);
  const std::string list_path = argv[3], out_path = argv[4];
  if (k < 2 || levels < 1) {
    std::cerr << "train_vocabulary: K must be >= 2 and L >= 1\n";
    return 2;
  }
  std::ifstream list(list_path);
  if (!list) {
    std::cerr << "train_vocabulary: cannot read " << list_path << "\n";
    return 1;
  }
  std::vector<std::string> images;
  for (std::string line; std::getline(list, line);)
    if (!line.empty() && line[0] != '#') images.push_back(line);
  if (images.empty()) {
    std::cerr << "train_vocabulary: " << list_path << " lists no image\n";
    return 1;
  }

  const auto t0 = std::chrono::steady_clock::now();
  ORB_SLAM2::ORBextractor extractor(2000, 1.2f, 8, 20, 7);
  std::vector<std::vector<cv::Mat>> features;
  features.reserve(images.size());
  size_t n_desc = 0;
  for (const std::string& path : images) {
    cv::Mat im = cv::imread(path, cv::IMREAD_GRAYSCALE);
    if (im.empty()) {
      std::cerr << "train_vocabulary: cannot load " << path << "\n";
      return 1;
    }
    std::vector<cv::KeyPoint> keypoints;
    cv::Mat descriptors;
    extractor(im, cv::Mat(), keypoints, descriptors);
    std::vector<cv::Mat> rows;
    rows.reserve(descriptors.rows);
    for (int r = 0; r < descriptors.rows; ++r) rows.push_back(descriptors.row(r).clone());
    n_desc += rows.size();
    features.push_back(std::move(rows));
  }
  const double extract_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  std::cerr << "train_vocabulary: " << images.size() << " images, " << n_desc
            << " ORB descriptors in " << extract_s << " s; clustering k=" << k << " L=" << levels
            << "\n";

  DUtils::Random::SeedRandOnce(20261203);
  DBoW2::TemplatedVocabulary<DBoW2::FORB::TDescriptor, DBoW2::FORB> voc(k, levels, DBoW2::TF_IDF,
                                                                        DBoW2::L1_NORM);
  voc.create(features);
  const double total_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  const std::string tmp = out_path + ".tmp";
  voc.saveToTextFile(tmp);
  if (std::rename(tmp.c_str(), out_path.c_str()) != 0) {
    std::cerr << "train_vocabulary: cannot rename " << tmp << " to " << out_path << "\n";
    return 1;
  }
  std::cout << "images " << images.size() << "\ndescriptors " << n_desc << "\nk " << k << "\nL "
            << levels << "\nwords " << voc.size() << "\nseconds " << total_s << "\n";
  return 0;
}
