/* replay.h: the replay main of the fuzz targets (built without libFuzzer,
 * e.g. under ctest and the sanitizer build): every file named, and every
 * file below every folder named, is given to the target's `one` in turn. */
#ifndef FUZZ_REPLAY_H
#define FUZZ_REPLAY_H

/* Replay paths[0..n): a path that does not exist is skipped with a note
 * (a corpus never made, or one a fuzzer is reducing); prints
 * "NAME: replayed N file(s)".  Returns non-zero when a folder could not
 * be read or `one` returned non-zero for a file. */
int fuzz_replay(const char *name, char *const *paths, int n, int (*one)(const char *path));

#endif
