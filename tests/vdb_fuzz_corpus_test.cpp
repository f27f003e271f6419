// The VDB fuzzer's seed corpus (fuzz/vdb_corpus/, docs/testing.md): tiny grids written by the
// test helpers with OpenVDB's own API, one as NanoVDB, and copies cut short. OpenVDB writes a
// fresh UUID into every file, so the files are not compared byte for byte; the test checks that
// the corpus is there and that each file reads as the fuzzer expects, to a grid or to a VdbError.
// NIMBUS_WRITE_FUZZ_CORPUS=1 (re)writes it.

#include <gtest/gtest.h>

#include <cstdint>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>
#include <vector>

#include "nimbus/media/vdb_density.h"
#include "support/vdb_grids.h"

namespace nimbus {
namespace vdb_fuzz_corpus_test {

namespace fs = std::filesystem;

const std::string kCorpus = std::string(NIMBUS_SOURCE_DIR) + "/fuzz/vdb_corpus/";

// The file cut to `fraction` of its size.
void write_cut(const std::string& from, const std::string& to, double fraction) {
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
  fs::resize_file(to, static_cast<std::uintmax_t>(fs::file_size(from) * fraction));
}

// The file with `bytes` written at `offset`.
void patch(const std::string& from, const std::string& to, std::uint64_t offset,
           const std::vector<unsigned char>& bytes) {
  fs::copy_file(from, to, fs::copy_options::overwrite_existing);
  std::fstream f(to, std::ios::in | std::ios::out | std::ios::binary);
  f.seekp(static_cast<std::streamoff>(offset));
  f.write(reinterpret_cast<const char*>(bytes.data()), static_cast<std::streamsize>(bytes.size()));
}

// Grids of one leaf (8³ voxels) around the origin, so that the files stay small and the
// fuzzer's probes meet their voxels. A NanoVDB grid's upper and lower nodes alone take 300 kB,
// so the NanoVDB seed is only its first 16 kB, which holds the header and the root: what
// libFuzzer keeps of it anyway at -max_len=16384.
void write_corpus() {
  fs::create_directories(kCorpus);
  test::write_linear_vdb(kCorpus + "linear8.vdb", 0, 7, 1.0, {-4, -4, -4});
  test::write_linear_vdb(kCorpus + "linear4.vdb", 0, 3, 2.0, {-4, -4, -4});
  test::write_nvdb(kCorpus + "linear8.vdb", kCorpus + "linear8.nvdb");
  fs::resize_file(kCorpus + "linear8.nvdb", 16384);
  write_cut(kCorpus + "linear8.vdb", kCorpus + "linear8_cut_half.vdb", 0.5);
  write_cut(kCorpus + "linear8.vdb", kCorpus + "linear8_cut_90.vdb", 0.9);
  write_cut(kCorpus + "linear4.vdb", kCorpus + "linear4_cut_header.vdb", 0.1);
  // The fuzzer's first findings, fixed in the reader (vdb_module_openvdb.cpp): a grid's name longer
  // than the file, and one without its terminating zero, which NanoVDB's header reader trusts.
  const std::uint64_t name_size = test::nvdb_name_size_offset();
  const std::uint64_t name = test::nvdb_name_offset();
  patch(kCorpus + "linear8.nvdb", kCorpus + "linear8_long_name.nvdb", name_size,
        {0xf0, 0xff, 0xff, 0xff});
  patch(kCorpus + "linear8.nvdb", kCorpus + "linear8_unterminated_name.nvdb", name + 7, {'x'});
}

TEST(VdbFuzzCorpus, EveryFileReadsToAGridOrAVdbError) {
  if (std::getenv("NIMBUS_WRITE_FUZZ_CORPUS")) write_corpus();
  int grids = 0, errors = 0;
  for (const auto& entry : fs::directory_iterator(kCorpus)) {
    EXPECT_LE(fs::file_size(entry.path()), 16384u) << entry.path() << ": the seeds stay small";
    VdbParams p;
    p.file = entry.path().string();
    try {
      const DensityPtr d = make_vdb_density(p);
      EXPECT_GT(d->value({0, 0, 0}, 1), 0) << p.file;
      ++grids;
    } catch (const VdbError& e) {
      EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << e.what();
      ++errors;
    }
  }
  EXPECT_EQ(grids, 2) << "linear8.vdb, linear4.vdb (NIMBUS_WRITE_FUZZ_CORPUS=1 writes them)";
  EXPECT_EQ(errors, 6);
}

}  // namespace vdb_fuzz_corpus_test
}  // namespace nimbus
