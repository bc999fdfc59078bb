/* libhomcull.so is the static core linked whole (lib/CMakeLists.txt); this unit only checks,
 * with a C compiler, that homcull.h is C99 as the library sees it. */
#include <homcull/homcull.h>
