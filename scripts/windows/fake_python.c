/* A stand-in for Python in scripts/windows_check.py's interruption check: it answers
 * modal-bake's gmsh version probe (`python -c "...print(gmsh.__version__)" DIR`) with a
 * version and hangs on any other run (the meshing), so the check can interrupt modal-bake
 * while a mesher child and its work folder exist. */
#include <windows.h>
#include <stdio.h>
#include <string.h>

int main(int argc, char **argv) {
    if (argc > 2 && strstr(argv[2], "__version__")) {
        printf("4.15.2\n");
        return 0;
    }
    Sleep(300000);
    return 0;
}
