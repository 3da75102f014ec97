/* ProcessPrng, which Rust's standard library draws its random keys from, for Wine 8 (Debian 12),
 * whose bcryptprimitives.dll does not exist yet: Windows 10 and 11 have it. Built by
 * scripts/windows_check.py and put beside the program it runs under Wine; never shipped. */
#include <windows.h>
#define SystemFunction036 NTAPI SystemFunction036
#include <ntsecapi.h>
#undef SystemFunction036

BOOL WINAPI ProcessPrng(PBYTE data, SIZE_T len) {
    while (len > 0) {
        ULONG n = len > 0x40000000 ? 0x40000000 : (ULONG)len;
        if (!RtlGenRandom(data, n)) return FALSE;
        data += n;
        len -= n;
    }
    return TRUE;
}
