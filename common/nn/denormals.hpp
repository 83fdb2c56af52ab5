// Flushing denormal floats to zero while the networks compute.
#pragma once

#if defined(__SSE__)
#include <xmmintrin.h>
#endif

namespace auvrl::nn {

/// While alive, the calling thread treats denormal floats as zero and flushes denormal results
/// to zero (x86: MXCSR's DAZ and FTZ bits; AArch64: FPCR.FZ); the previous mode comes back at
/// the end. Why: weights that L2 decay pulls toward zero, and what flows through them, reach
/// the denormal range after some thousands of updates, and every product with a denormal operand
/// is microcoded on x86 (~100 times slower): a 64-64 DDPG benchmark fell from 5,600 to 360
/// updates/s. TensorFlow flushes denormals the same way. Every forward, backward, Adam step and
/// soft update of this library holds one.
class ScopedFlushDenormals {
 public:
  ScopedFlushDenormals() noexcept {
#if defined(__SSE__)
    saved_ = _mm_getcsr();
    _mm_setcsr(saved_ | kDazFtz);
#elif defined(__aarch64__)
    __asm__ __volatile__("mrs %0, fpcr" : "=r"(saved_));
    __asm__ __volatile__("msr fpcr, %0" ::"r"(saved_ | kFz));
#endif
  }
  ~ScopedFlushDenormals() {
#if defined(__SSE__)
    _mm_setcsr(saved_);
#elif defined(__aarch64__)
    __asm__ __volatile__("msr fpcr, %0" ::"r"(saved_));
#endif
  }
  ScopedFlushDenormals(const ScopedFlushDenormals&) = delete;
  ScopedFlushDenormals& operator=(const ScopedFlushDenormals&) = delete;

 private:
#if defined(__SSE__)
  static constexpr unsigned int kDazFtz = 0x8040;  // FTZ (bit 15) | DAZ (bit 6)
  unsigned int saved_ = 0;
#elif defined(__aarch64__)
  static constexpr unsigned long kFz = 1ul << 24;
  unsigned long saved_ = 0;
#endif
};

}  // namespace auvrl::nn
