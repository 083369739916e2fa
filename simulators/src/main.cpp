// lamina-sim: placeholder until the process loop lands (issue 5, in progress).
#include <cstdio>
int main() {
  std::fputs("lamina-sim: not built yet\n", stderr);
  return 2;
}
