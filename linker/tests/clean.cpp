// Keeps the rule: plain arithmetic on caller-owned storage, for the check's passing case.
int sum(const int* values, int count) {
  int total = 0;
  for (int i = 0; i < count; ++i) {
    total += values[i];
  }
  return total;
}
