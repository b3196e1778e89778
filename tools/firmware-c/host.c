/*
 * The C example on the host (tools/ffi-check.sh): example.c linked with the
 * host's libpalpate_ffi.a, the table read from a file into a 16-byte-aligned
 * buffer, output to stdout. `host TABLE`; exit status 0 on success.
 */
#include <stdio.h>
#include <stdlib.h>

#include "example.h"

void example_write(const char *text, size_t len) { fwrite(text, 1, len, stdout); }

void example_wait_tick(void) {}

int main(int argc, char **argv) {
    if (argc != 2) {
        fprintf(stderr, "usage: %s TABLE\n", argv[0]);
        return 2;
    }
    FILE *file = fopen(argv[1], "rb");
    if (file == NULL || fseek(file, 0, SEEK_END) != 0) {
        perror(argv[1]);
        return 2;
    }
    long len = ftell(file);
    /* aligned_alloc wants a multiple of the alignment. */
    unsigned char *bytes = len > 0 ? aligned_alloc(16, ((size_t)len + 15) / 16 * 16) : NULL;
    if (bytes == NULL || fseek(file, 0, SEEK_SET) != 0 ||
        fread(bytes, 1, (size_t)len, file) != (size_t)len) {
        perror(argv[1]);
        return 2;
    }
    fclose(file);
    int status = example_run(bytes, (size_t)len);
    free(bytes);
    return status;
}
