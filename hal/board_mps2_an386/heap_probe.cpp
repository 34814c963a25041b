// Must not link (ctest board_image_refuses_*): an image that allocates. PLINTH_PROBE_NEW selects
// operator new, otherwise malloc.
#include <cstdlib>

#include "plinth/hal/board.h"

extern "C" int plinth_board_main() {
#ifdef PLINTH_PROBE_NEW
  int* volatile p = new int(1);
#else
  void* volatile p = std::malloc(16);
#endif
  return p != nullptr ? 0 : 1;
}
