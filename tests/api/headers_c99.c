/* The installed C headers on their own, compiled as C99 with -pedantic -Werror (target
 * mcd_header_check). */
#include <mcdenoise/io_c.h>
#include <mcdenoise/mcdenoise_c.h>

int mcdHeaderCheck(void);
int mcdHeaderCheck(void) {
    MCDView view = mcdInterleaved(0, MCD_FORMAT_HALF, 1, 1, 1);
    return view.format == MCD_FORMAT_HALF && MCD_ERROR_CANCELLED == 8;
}
