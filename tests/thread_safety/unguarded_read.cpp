// The thread-safety stage's proof that the analysis is live (cmake/thread_safety.cmake): this
// file must fail to compile with -Wthread-safety -Werror=thread-safety, because read() takes a
// COSMIC_GUARDED_BY member without its mutex. Built with COSMIC_TSA_LOCKED it takes the lock and
// must compile, which shows that the failure is the analysis and not a broken include path.
#include "cosmic/mutex.hpp"
#include "cosmic/pi_mutex.hpp"
#include "cosmic/thread_annotations.hpp"

namespace {

class Counter {
 public:
  int read() {
#ifdef COSMIC_TSA_LOCKED
    cosmic::PiLock lock(mutex_);
#endif
    return value_;
  }
  void add(int n) {
    cosmic::LockGuard lock(other_mutex_);
    other_ += n;
  }

 private:
  cosmic::PiMutex mutex_;
  int value_ COSMIC_GUARDED_BY(mutex_) = 0;
  cosmic::Mutex other_mutex_;
  int other_ COSMIC_GUARDED_BY(other_mutex_) = 0;
};

}  // namespace

int main() {
  Counter counter;
  counter.add(1);
  return counter.read();
}
