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
# Process-level repeats of paths that cheaper tests run under the sanitizers: resuming after a
# kill (Checkpoints.Interrupted*), MPI (Mpi.RanksRenderToANoiseTarget*), the noise target's passes
# (NoiseTarget.BlocksStop*), the sampling pass (the Sampled modes), the member grid's lookups
# (ManyMedia's walks), compiling on many threads (every scene test compiles on them).
repeats+=':Checkpoints.KilledAndResumedIsTheUninterruptedRender'
repeats+=':Mpi.ARankKilledLeavesNoOutputAndTheCheckpointResumes'
repeats+=':Job.ToANoiseTargetTheSameBitsInPassesInUnitsAndResumed'
repeats+=':Octree.SamplingPassWorkIsBounded'
repeats+=':ManyMedia.PointLookupsEqualTheLoopOverEveryObjectToTheBit'
repeats+=':Scenes.ObjectsCompileTheSameOnOneThreadAsOnMany'
# The render families under the sanitizers in the modes whose code differs: Woodcock's, the
# weighted trackers' with decomposition (at both octree extremes, with failing and sampled
# majorants), spectral MIS, and ray marching once. The rest run in the Release pass.
for mode in SpectralHistoryWeightDepth4 SpectralHistoryWeightDecompositionDepth0 \
  SpectralHistoryWeightDecompositionRayMarchingDepth4 \
  SpectralHistoryWeightDecompositionUnboundedRayMarchingDepth4 'DeltaWeight*' \
  'SpectralHistoryCollide*' 'DeltaCollideDecomposition*'; do
  repeats+=":Modes/MediaRender.*/$mode:Modes/SpectralRender.*/$mode"
done
filter="*:-$repeats"
[ "${1:-}" = "--all" ] && filter='*'
sanitized_tests() { suites build-sanitize "$filter" -E "$never"; }
phase "sanitized configure" bash tools/configure.sh sanitize
phase "sanitized build" cmake --build build-sanitize -j"$(nproc)"
phase "sanitized tests" sanitized_tests
phase "fuzzing" bash tools/fuzz.sh --runs 100000 "$(nproc)"
phase "fuzzing the file readers" bash tools/fuzz.sh --files --runs 20000 "$(nproc)"
