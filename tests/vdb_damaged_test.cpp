// Damaged .vdb files that the VDB fuzzer found (docs/testing.md, "The VDB reader's fuzzer"):
// OpenVDB itself allocates what their length fields claim (13 GB for one 10 kB file) or fails
// deep in its decompression. Read in a child process (VdbParams::isolate_reader), each gives a
// one-line VdbError that names the file, and this process stays small.

#include <gtest/gtest.h>
#include <sys/resource.h>

#include <string>

#include "nimbus/media/vdb_density.h"
#include "support/sanitizer.h"

namespace nimbus {
namespace vdb_damaged_test {

const std::string kDamaged = std::string(NIMBUS_SOURCE_DIR) + "/tests/data/vdb_damaged/";

std::string error_of(const std::string& name) {
  VdbParams p;
  p.file = kDamaged + name;
  try {
    make_vdb_density(p);
  } catch (const VdbError& e) {
    EXPECT_EQ(e.key, "file");
    return e.what();
  }
  ADD_FAILURE() << name << " was read as a grid";
  return "";
}

long max_resident_kib() {
  rusage u{};
  getrusage(RUSAGE_SELF, &u);
  return u.ru_maxrss;
}

TEST(VdbDamaged, EachFileIsOneLineNamingIt) {
  for (const char* name :
       {"metadata_length_13gb.vdb", "metadata_length.vdb", "blosc_size.vdb", "lookup_900mb.vdb"}) {
    const std::string message = error_of(name);
    EXPECT_EQ(message.find('\n'), std::string::npos) << message;
    EXPECT_EQ(message.rfind(kDamaged + name + ": ", 0), 0u) << message;
    EXPECT_NE(message.find("OpenVDB file"), std::string::npos) << message;
  }
}

TEST(VdbDamaged, AHugeAllocationStopsAtTheChildsLimitNotInThisProcess) {
  const std::string message = error_of("metadata_length_13gb.vdb");
  // Under AddressSanitizer the child's allocator aborts instead of throwing std::bad_alloc.
  const char* stop = test::kAddressSanitizer ? "OpenVDB's reader" : "needed more than 1.1 GB";
  EXPECT_NE(message.find(stop), std::string::npos) << message;
  EXPECT_LT(max_resident_kib(), 512 * 1024) << "read in this process, not in a child";
}

}  // namespace vdb_damaged_test
}  // namespace nimbus
