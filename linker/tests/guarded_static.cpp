// Breaks the rule on purpose: a function-local static with a run-time initialiser takes a guard lock.
int read_setting(int seed);
int cached_setting(int seed) {
  static const int setting = read_setting(seed);
  return setting;
}
