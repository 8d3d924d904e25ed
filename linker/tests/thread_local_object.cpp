// Breaks the rule on purpose: a thread_local object with a destructor registers it (and allocates).
struct Scratch {
  Scratch();
  ~Scratch();
  int value;
};
int use_scratch() {
  thread_local Scratch scratch;
  return scratch.value;
}
