// Breaks the rule on purpose: blocks on a condition variable.
#include <condition_variable>
#include <mutex>
std::mutex state_lock;
std::condition_variable state_changed;
bool ready = false;
void wait_until_ready() {
  std::unique_lock<std::mutex> guard(state_lock);
  state_changed.wait(guard, [] { return ready; });
}
