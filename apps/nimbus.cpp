#include <cstdio>
int main() {
  std::printf("nimbus %s\n", NIMBUS_VERSION);
  return 0;
}
