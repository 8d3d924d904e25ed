// Breaks the rule on purpose: takes a mutex.
#include <mutex>
std::mutex shared_lock;
int shared_value = 0;
void bump() {
  std::lock_guard<std::mutex> guard(shared_lock);
  ++shared_value;
}
