// libFuzzer target: COLMAP's matching on any database that SPHERA's check
// (colmap_ext/scene/database_check) lets through, end to end. The input is
// written as a database file; when the check passes, the geometric verifier
// reads its keypoints and raw matches and verifies every matched pair, then
// the exhaustive matcher reads its keypoints and descriptors, matches every
// pair anew and verifies it, and the result is checked as matching
// commands check it (NoVerifiedPairError).
//
// The check and the camera parameter check are instrumented (the coverage
// that guides the fuzzer), COLMAP's matching is linked from the build. A
// database the check accepts must not end the matching threads: an
// exception that leaves one of them, a signal or a sanitizer report is a
// failure of this target (libFuzzer keeps the input), since it means that
// the check lets through a database that matching cannot read.
#include "colmap/controllers/feature_matching.h"
#include "colmap/controllers/pairing.h"
#include "colmap/estimators/two_view_geometry.h"
#include "colmap/feature/matcher.h"
#include "colmap/scene/database.h"
#include "colmap_ext/scene/database_check.h"
#include "tests/fuzz/database_input.h"

#include <cstddef>
#include <cstdint>
#include <exception>
#include <stdexcept>
#include <string>

namespace {

void RunThread(colmap::Thread* thread) {
  thread->Start();
  thread->Wait();
}

// The geometric verifier, then the exhaustive matcher, on the database at
// `path`. One thread each, on the CPU: the same work in the same order for
// every run of an input.
void Match(const std::string& path) {
  colmap::TwoViewGeometryOptions geometry_options;
  geometry_options.ransac_options.random_seed = 1;
  geometry_options.ransac_options.max_num_trials = 200;
  {
    colmap::GeometricVerifierOptions verifier_options;
    verifier_options.num_threads = 1;
    colmap::ExistingMatchedPairingOptions pairing_options;
    auto verifier = colmap::CreateGeometricVerifier(
        verifier_options, pairing_options, geometry_options, path);
    RunThread(verifier.get());
  }
  {
    // The raw matches and their verification are made anew: the matcher
    // skips the pairs the database already holds.
    auto database = colmap::Database::Open(path);
    database->ClearMatches();
    database->ClearTwoViewGeometries();
  }
  {
    colmap::FeatureMatchingOptions matching_options;
    matching_options.num_threads = 1;
    matching_options.use_gpu = false;
    colmap::ExhaustivePairingOptions pairing_options;
    auto matcher = colmap::CreateExhaustiveFeatureMatcher(
        pairing_options, matching_options, geometry_options, path);
    RunThread(matcher.get());
  }
  // The matching commands' own verdict: a named error or nothing.
  (void)colmap::NoVerifiedPairError(path, geometry_options.min_num_inliers);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const uint8_t* data, size_t size) {
  const std::string path =
      sphera_fuzz::WriteDatabaseInput("fuzz_matching", data, size);
  if (path.empty()) {
    return 0;
  }
  try {
    colmap::CheckDatabaseFile(path, 4020000);
  } catch (const std::runtime_error&) {
    // A named error: nothing reaches matching.
    sphera_fuzz::RemoveDatabase(path);
    return 0;
  }
  try {
    Match(path);
  } catch (const std::exception&) {
    // Raised on the calling thread, as by the matchers' own checks ("no
    // images to match"): the command names it and exits 1.
  }
  sphera_fuzz::RemoveDatabase(path);
  return 0;
}
