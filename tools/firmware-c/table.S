/* The pre-computed table (`palpate tables build`, f32) linked into flash,
   16-byte aligned as palpate_precomputed_table_load requires; the Makefile
   passes its path as PALPATE_TABLE_FILE. */
    .section .palpate_table, "a"
    .balign 16
    .global palpate_table_start
palpate_table_start:
    .incbin PALPATE_TABLE_FILE
    .global palpate_table_end
palpate_table_end:
