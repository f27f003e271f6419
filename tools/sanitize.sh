#!/usr/bin/env bash
# The sanitized pass of the test suite (docs/testing.md): builds with clang, AddressSanitizer and
# UndefinedBehaviorSanitizer in build-sanitize/ (tools/configure.sh sanitize), runs the suite
# there, then fuzzes the committed corpus for a fixed number of inputs. Assumes tools/setup.sh
# has run.
#   tools/sanitize.sh         the CI tier: the suite less the repeats below
#   tools/sanitize.sh --all   every test that can run under the sanitizers
#
# The GoogleTest binary runs in 16 shards (tools/gtest_shards.sh) rather than a process per test
# (one start costs 0.2 s of CPU under the sanitizers); the scripted tests run under ctest.
# Never run here: the packaging test (the example it builds is not instrumented) and the image
# checksums (recorded from the Release g++ build, which a clang build need not match to the last
# bit). Left to --all and to the Release pass, which runs them all: the render-test instances
# that repeat, on costlier scenes, code paths that cheaper instances already cover under the
# sanitizers (docs/testing.md, "Tiers"). The VDB fuzz corpus is not fuzzed here: its damaged files
# make OpenVDB itself request allocations that AddressSanitizer aborts on (a Release build gets
# std::bad_alloc and the one-line error the test checks).
set -euo pipefail
cd "$(dirname "$0")/.."
source tools/phase.sh
never='^InstallAndEmbed$|^ImageChecksums$'
repeats='Modes/MediaRender.Chandrasekhar*:Modes/MediaRender.EmittingField*'
repeats+=':Modes/MediaRender.SingleScattering*:Modes/SpectralRender.Chandrasekhar*'
repeats+=':Modes/SpectralRender.EmittingField*:Modes/SpectralRender.SingleScattering*'
repeats+=':Modes/SpectralRender.EmissiveFurnace*'
repeats+=':Modes/MediaRender.EmissiveFurnaceIsInEquilibrium/*Unbounded*'
repeats+=':ManyMedia.OverlappingCopiesRenderAsTheirSum'
repeats+=':RayMarchingTransmittance.MatchesAnalyticTransmittance'
repeats+=':ManifoldRender.NarrowingConesTendToTheDirectionalLight'
repeats+=':ManifoldRender.ShrinkingSphereLightsTendToThePointLight'
repeats+=':Modes/MediaRender.WhiteFurnaceCloudDensityIndexMatched/*Unbounded*'
repeats+=':Modes/MediaRender.*/*Depth12'
for family in WhiteFurnaceCloudDensityIndexMatched WhiteFurnaceBehindLosslessDielectric \
  EmissiveFurnaceIsInEquilibrium; do
  repeats+=":Modes/MediaRender.$family/Delta*:Modes/MediaRender.$family/SpectralHistoryCollide*"
done
repeats+=':FirstHit.AgreesWithBruteForceOnTheGallery'
repeats+=':Modes/MediaRender.EmissionPerLengthFurnaceIsInEquilibrium/*Unbounded*'
repeats+=':Modes/MediaRender.EmissionPerLengthFurnaceIsInEquilibrium/*Depth0'
repeats+=':NoiseTarget.BlocksThatStopEarlyAreNeitherBrighterNorDarkerThanThoseThatRunLong'
filter="*:-$repeats"
[ "${1:-}" = "--all" ] && filter='*'
sanitized_tests() { suites build-sanitize "$filter" -E "$never"; }
phase "sanitized configure" bash tools/configure.sh sanitize
phase "sanitized build" cmake --build build-sanitize -j"$(nproc)"
phase "sanitized tests" sanitized_tests
phase "fuzzing" bash tools/fuzz.sh --runs 200000 "$(nproc)"
phase "fuzzing the file readers" bash tools/fuzz.sh --files --runs 40000 "$(nproc)"
