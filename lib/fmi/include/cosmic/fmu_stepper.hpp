// The paper's "get event" for an FMU (issue 38, docs/fmu.md "Stepping"): each communication step
// takes, for each input channel, the last event that arrived before the step (counting the ones it
// skipped), sets the mapped input variables, calls doStep, reads the output variables and makes each
// output channel's whole event. The runner (cosmic-fmu) moves the events and keeps the time.
//
// Owns the per-channel codecs and latches; uses the FmuInstance and the configuration it is given,
// which outlive it. Threads: InputLatch::offer() from any receive thread; everything else from the
// one thread that steps (the FmuInstance's). No I/O of its own.
#pragma once

#include <cstdint>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "cosmic/fmu_channel_fields.hpp"
#include "cosmic/fmu_instance.hpp"
#include "cosmic/model.hpp"
#include "cosmic/mutex.hpp"
#include "cosmic/pi_mutex.hpp"

namespace cosmic::fmi {

// The newest event of one input channel, waiting for the next step.
class InputLatch {
 public:
  // A receive thread hands an event over (copied; the previous one not yet taken is replaced).
  void offer(std::span<const std::uint8_t> event);
  // The step thread takes the newest event into `event` (swapped, so both buffers are reused): false
  // when none arrived since the last take. `arrived` says how many arrived since then (1 + skipped).
  bool take(std::vector<std::uint8_t>& event, std::uint64_t& arrived);

 private:
  // Priority-inheriting: the step thread may run SCHED_FIFO (cosmic-fmu --priority), the client's
  // receive threads time-shared; a receive thread holding the latch is lifted while it copies.
  PiMutex mutex_;
  std::vector<std::uint8_t> pending_ COSMIC_GUARDED_BY(mutex_);
  std::uint64_t arrived_ COSMIC_GUARDED_BY(mutex_) = 0;
};

// What the steps so far did, per input and output channel.
struct InputCounters {
  std::string channel;
  std::uint64_t taken = 0;          // events the steps used
  std::uint64_t skipped = 0;        // events a newer one replaced before a step took it
  std::uint64_t decode_errors = 0;  // events that were not one event of the channel's type, or held an
                                    // enumeration value that is none of the variable's items (not set)
  std::uint64_t clipped = 0;        // values beyond their variable's range, saturated (counted per value)
};
struct OutputCounters {
  std::string channel;
  std::uint64_t events = 0;   // events made (one per step)
  std::uint64_t clipped = 0;  // values an output field could not hold (saturated, counted per value)
};

class FmuStepper {
 public:
  // Checks that every mapped variable and field exists as the configuration said; the instance must
  // be freshly instantiated (start() sets its parameters and initializes it).
  static Result<std::unique_ptr<FmuStepper>> make(const FmuSpec& spec, const FmuDescription& description,
                                                  const Config& config, FmuInstance& instance);

  // The parameters set, then the FMU initialized at time 0.
  Result<void> start();
  // Step `index` (from time index*step over one step): inputs, doStep, outputs. After an error the
  // FMU is unusable; instance().recent_log() has its messages.
  Result<void> step(std::uint64_t index);

  std::size_t input_count() const { return inputs_.size(); }
  const std::string& input_channel(std::size_t i) const { return inputs_[i].channel; }
  InputLatch& latch(std::size_t i) { return *inputs_[i].latch; }
  std::size_t output_count() const { return outputs_.size(); }
  const std::string& output_channel(std::size_t i) const { return outputs_[i].channel; }
  // Output channel i's event of the last step (compact layout).
  std::span<const std::uint8_t> output_event(std::size_t i) const { return outputs_[i].event; }

  std::vector<InputCounters> input_counters() const;
  std::vector<OutputCounters> output_counters() const;
  // The counters into the caller's vectors: the channel names copied once, the numbers at every
  // call, so a step that calls it allocates nothing after the first.
  void copy_counters(std::vector<InputCounters>& inputs, std::vector<OutputCounters>& outputs) const;
  double step_seconds() const { return step_seconds_; }
  FmuInstance& instance() { return instance_; }

 private:
  struct Input {
    std::string channel;
    std::unique_ptr<InputLatch> latch = std::make_unique<InputLatch>();
    ChannelFields fields;
    std::vector<const Variable*> variables;  // slot -> variable
    std::vector<std::uint8_t> event;         // the taken event (reused)
    std::vector<FieldValue> values;          // slot values (reused)
    InputCounters counters;
  };
  struct Output {
    std::string channel;
    ChannelFields fields;
    std::vector<const Variable*> variables;
    std::vector<std::uint8_t> event;
    std::vector<FieldValue> values;
    OutputCounters counters;
  };

  FmuStepper(const FmuSpec& spec, const FmuDescription& description, FmuInstance& instance)
      : spec_(spec), description_(description), instance_(instance), step_seconds_(to_seconds(spec.step)) {}
  static double to_seconds(Nanos step) { return static_cast<double>(step.count()) / 1e9; }
  Result<void> take_inputs();
  Result<void> make_outputs();

  const FmuSpec& spec_;
  const FmuDescription& description_;
  FmuInstance& instance_;
  double step_seconds_;
  std::vector<Input> inputs_;
  std::vector<Output> outputs_;
};

}  // namespace cosmic::fmi
