#include "fmu_runner.hpp"

#include <time.h>

#include <cerrno>

namespace cosmic_fmu {
namespace {

using Clock = std::chrono::steady_clock;

cosmic_class class_of(cosmic::ChannelClass c) {
  switch (c) {
    case cosmic::ChannelClass::hrt:
      return COSMIC_HRT;
    case cosmic::ChannelClass::srt:
      return COSMIC_SRT;
    case cosmic::ChannelClass::nrt:
      break;
  }
  return COSMIC_NRT;
}

std::int64_t ns(const std::optional<cosmic::Nanos>& d) { return d ? d->count() : 0; }

bool has(const std::vector<std::string>& names, const std::string& name) {
  return std::find(names.begin(), names.end(), name) != names.end();
}

// Sleeps until `when` on the monotonic clock steady_clock reads; returns early on a signal.
void sleep_until(Clock::time_point when) {
  const auto since_epoch = std::chrono::duration_cast<std::chrono::nanoseconds>(when.time_since_epoch());
  timespec ts{};
  ts.tv_sec = static_cast<time_t>(since_epoch.count() / 1'000'000'000);
  ts.tv_nsec = static_cast<long>(since_epoch.count() % 1'000'000'000);
  ::clock_nanosleep(CLOCK_MONOTONIC, TIMER_ABSTIME, &ts, nullptr);  // EINTR: the caller looks at its stop flag
}

}  // namespace

cosmic::Result<std::unique_ptr<FmuRunner>> FmuRunner::open(const cosmic::Config& config, const cosmic::FmuSpec& spec,
                                                           const RunnerOptions& options, cosmic::Logger& log) {
  auto work = WorkDirectory::make(options.work_parent, spec.name);
  if (!work) return work.error();
  std::unique_ptr<FmuRunner> runner(new FmuRunner(config, spec, options, log, std::move(work.value())));
  auto opened = cosmic::fmi::open_fmu(spec.fmu, runner->work_.path() + "/fmu");
  if (!opened.ok()) {
    std::string why;
    for (const auto& e : opened.errors) why += (why.empty() ? "" : "; ") + e;
    return cosmic::Error{why};
  }
  runner->fmu_ = std::move(opened.fmu);
  auto instance = cosmic::fmi::instantiate(runner->fmu_, {spec.name, true});
  if (!instance) return instance.error();
  runner->instance_ = std::move(instance.value());
  auto stepper = cosmic::fmi::FmuStepper::make(spec, runner->fmu_.description, config, *runner->instance_);
  if (!stepper) return stepper.error();
  runner->stepper_ = std::move(stepper.value());
  if (auto started = runner->stepper_->start(); !started)
    return cosmic::Error{"initialization failed: " + started.error().text + "\n" +
                         runner->instance_->recent_log_text()};
  if (auto joined = runner->join_channels(); !joined) return joined.error();
  if (!options.trace_file.empty()) {
    runner->trace_.open(options.trace_file, std::ios::trunc);
    if (!runner->trace_) return cosmic::Error{"cannot write the trace file " + options.trace_file};
    runner->trace_header();
  }
  return runner;
}

FmuRunner::~FmuRunner() {
  subscriptions_.clear();  // no handler touches a latch once they are gone
  if (client_) client_->close();
}

cosmic::Result<void> FmuRunner::join_channels() {
  const cosmic::SegmentSpec* segment = config_.find_segment(spec_.segment);
  if (segment == nullptr) return cosmic::Error{"unknown segment '" + spec_.segment + "'"};
  try {
    client_ = std::make_unique<cosmic::client::Client>(cosmic::client_segment(*segment, options_.can_node));
    const auto publishes = spec_.publishes();
    const auto subscribes = spec_.subscribes();
    std::map<std::string, cosmic::client::Channel*> announced;
    for (const auto& name : config_.channels) {
      const bool out = has(publishes, name.name), in = has(subscribes, name.name);
      if (!out && !in) continue;
      const cosmic_channel_desc desc{name.name.c_str(),
                                     name.subject,
                                     class_of(name.cls),
                                     ns(name.period),
                                     ns(name.reaction_time),
                                     ns(name.temp_validity),
                                     name.omission_degree,
                                     static_cast<std::uint32_t>(name.payload),
                                     (out ? COSMIC_PUBLISH : 0) | (in ? COSMIC_SUBSCRIBE : 0)};
      announced[name.name] = &client_->announce(desc, 5000);
    }
    for (std::size_t i = 0; i < stepper_->input_count(); ++i) {
      cosmic::client::Channel* channel = announced.at(stepper_->input_channel(i));
      input_channels_.push_back(channel);
      cosmic::fmi::InputLatch* latch = &stepper_->latch(i);
      subscriptions_.push_back(
          channel->on_event([latch](const cosmic_event_info&, std::span<const std::uint8_t> e) { latch->offer(e); }));
    }
    for (std::size_t i = 0; i < stepper_->output_count(); ++i)
      output_channels_.push_back(announced.at(stepper_->output_channel(i)));
  } catch (const std::exception& e) {
    return cosmic::Error{std::string("joining the channels on segment '") + spec_.segment + "': " + e.what()};
  }
  return {};
}

// One deadline for every output channel, looked at in slices so that a stop is not held up by a
// gateway that is not there.
void FmuRunner::wait_until_carried(const std::atomic<bool>& stop) {
  constexpr std::chrono::milliseconds kSlice{100};
  const auto deadline = Clock::now() + options_.ready_timeout;
  for (cosmic::client::Channel* channel : output_channels_) {
    for (;;) {
      if (stop.load(std::memory_order_relaxed)) return;
      const auto left = std::chrono::duration_cast<std::chrono::milliseconds>(deadline - Clock::now());
      try {
        channel->wait_ready(std::clamp(left, std::chrono::milliseconds{0}, kSlice));
        break;
      } catch (const std::exception& e) {
        if (left > kSlice) continue;
        log_.log(cosmic::LogLevel::warning, std::string("stepping anyway: ") + e.what());
        return;
      }
    }
  }
}

cosmic::Result<void> FmuRunner::run(const std::atomic<bool>& stop) {
  wait_until_carried(stop);
  set_state(RunnerState::running);
  const auto step = std::chrono::duration_cast<Clock::duration>(spec_.step);
  Clock::time_point start = Clock::now();
  for (std::uint64_t k = 0; !stop.load(std::memory_order_relaxed) && (options_.steps == 0 || k < options_.steps); ++k) {
    const Clock::time_point begin_at = start + step * static_cast<Clock::rep>(k);
    if (options_.paced) {
      sleep_until(begin_at);
      if (stop.load(std::memory_order_relaxed)) break;
    }
    const Clock::time_point began = Clock::now();
    if (auto stepped = one_step(k); !stepped) {
      set_state(RunnerState::failed, stepped.error().text + "\n" + instance_->recent_log_text());
      return stepped;
    }
    const Clock::time_point ended = Clock::now();
    const Clock::time_point deadline = begin_at + step;
    const bool late = options_.paced && ended > deadline;
    timing_.record(ended - began, late, late ? ended - deadline : Clock::duration{});
    // A late step slips the schedule: the next step starts now, the ones after it a step apart. Run
    // back to back instead, the missed steps would publish faster than the step, which is the
    // output channels' admitted period.
    if (late) start = ended - step * static_cast<Clock::rep>(k + 1);
    if (instance_->ended()) {
      log_.log(cosmic::LogLevel::info,
               "fmu " + spec_.name + " ended the simulation at t=" +
                   cosmic::shortest_number_text(static_cast<double>(k + 1) * stepper_->step_seconds()) + " s");
      break;
    }
  }
  if (auto ended = instance_->terminate(); !ended) {
    set_state(RunnerState::failed, ended.error().text + "\n" + instance_->recent_log_text());
    return ended;
  }
  set_state(RunnerState::stopped);
  return {};
}

cosmic::Result<void> FmuRunner::one_step(std::uint64_t index) {
  if (auto stepped = stepper_->step(index); !stepped) return stepped;
  publish_outputs();
  if (trace_.is_open()) trace_step(index);
  {
    cosmic::LockGuard lock(status_mutex_);
    stepper_->copy_counters(inputs_, outputs_);  // numbers only after the first step: no allocation
  }
  return {};
}

void FmuRunner::publish_outputs() {
  for (std::size_t i = 0; i < output_channels_.size(); ++i) {
    if (output_channels_[i]->publish(stepper_->output_event(i)) != COSMIC_OK)
      publish_errors_.fetch_add(1, std::memory_order_relaxed);
  }
}

void FmuRunner::trace_header() {
  trace_ << "step,time";
  for (const auto& m : spec_.inputs) trace_ << ',' << m.variable;
  for (const auto& m : spec_.outputs) trace_ << ',' << m.variable;
  trace_ << '\n';
}

void FmuRunner::trace_step(std::uint64_t index) {
  trace_ << index << ',' << cosmic::shortest_number_text(static_cast<double>(index + 1) * stepper_->step_seconds());
  const auto column = [&](const cosmic::FmuVariableMapping& m) {
    const cosmic::fmi::Variable* v = fmu_.description.find_variable(m.variable);
    auto value = instance_->get(*v);
    trace_ << ',' << (value ? cosmic::fmi::to_string(value.value()) : std::string("?"));
  };
  for (const auto& m : spec_.inputs) column(m);
  for (const auto& m : spec_.outputs) column(m);
  trace_ << std::endl;  // line by line, so the trace can be followed while the FMU runs
}

void FmuRunner::set_state(RunnerState state, std::string message) {
  cosmic::LockGuard lock(status_mutex_);
  state_ = state;
  message_ = std::move(message);
}

RunnerStatus FmuRunner::status(bool take_window) const {
  RunnerStatus out;
  out.timing = timing_.snapshot(take_window);
  out.publish_errors = publish_errors_.load(std::memory_order_relaxed);
  cosmic::LockGuard lock(status_mutex_);
  out.state = state_;
  out.message = message_;
  out.inputs = inputs_;
  out.outputs = outputs_;
  return out;
}

}  // namespace cosmic_fmu
