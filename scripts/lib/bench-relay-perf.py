#!/usr/bin/python3
"""Where a process's CPU samples go, by thread: scripts/bench's relay-rates profile.

Reads `perf script -F tid,ip,sym,dso` of a `perf record -g` (one block per sample: a "TID" line,
then one frame per line, leaf first) on stdin and prints, for the threads with at least
--min-share percent of the samples: their share, what their samples were doing (the kernel path
that led to the leaf, or the user library), and their hottest leaf symbols. The kernel path is
told from the call chain, not the leaf: on a virtual machine without a PMU, perf samples with the
cpu-clock timer, and a sample that falls while interrupts are off lands where they come back on
(finish_task_switch after a context switch, _raw_spin_unlock_irqrestore after waking a thread),
so the leaf names the end of the path, the chain names the path.

usage: perf script -i DATA -F tid,ip,sym,dso | bench-relay-perf.py --names TID=NAME,... [--events N] [--freq HZ]
"""
import argparse
import collections
import re
import sys

# Kernel paths, by the first of these frames found in a sample's chain (leaf to root).
KERNEL_PATHS = [
    ("futex_wake", "waking another thread (futex wake)"),
    ("futex_wait", "sleeping and being woken (futex wait)"),
    ("exit_to_user_mode_loop", "preempted or rescheduled on the way back to user space"),
    ("irqentry_exit", "preempted or rescheduled after an interrupt"),
    ("do_epoll_wait", "sleeping and being woken (epoll)"),
    ("__sys_sendto", "sending a datagram (sendto/sendmsg)"),
    ("__sys_sendmsg", "sending a datagram (sendto/sendmsg)"),
    ("__sys_recvfrom", "receiving a datagram (recvfrom/recvmsg)"),
    ("__sys_recvmsg", "receiving a datagram (recvfrom/recvmsg)"),
    ("asm_exc_page_fault", "page faults"),
    ("asm_sysvec", "interrupts"),
    ("asm_common_interrupt", "interrupts"),
]
SYSCALL = re.compile(r"^__x64_sys_(\w+)")
# The code a sample was in: its innermost frame of Fast DDS or cosmicd (names shortened).
CODE = re.compile(r"eprosima::|cosmic::")
WAKE_OR_SLEEP = ("kernel: waking another thread (futex wake)", "kernel: sleeping and being woken (futex wait)",
                 "kernel: preempted or rescheduled on the way back to user space")
HEADER = re.compile(r"^\s*\d+\s*$")
# What a thread is, told from functions anywhere in its samples' chains (Fast DDS names its threads
# nothing cosmicd keeps: cosmicd names them after the segment).
ROLES = [
    ("EgressLane::worker", "cosmicd's egress lane (router -> DataWriter::write)"),
    ("on_data_available", "receives user data (listener -> take -> router)"),
    ("processDataMsg", "receives user data (listener -> take -> router)"),
    ("process_acknack", "processes ACKNACKs (a writer's readers acknowledging)"),
    ("convert_status_on_all_changes", "processes ACKNACKs (a writer's readers acknowledging)"),
    ("proc_Submsg_Heartbeat", "processes HEARTBEATs (a reader's writers announcing)"),
    ("perform_nack_supression", "Fast DDS's event thread: a writer's NACK-suppression timer"),
    ("do_timer_actions", "Fast DDS's event thread (heartbeat, ACKNACK and liveliness timers)"),
    ("event_service", "Fast DDS's event thread (heartbeat, ACKNACK and liveliness timers)"),
    ("SharedMemChannelResource", "shared-memory transport receive"),
    ("UDPChannelResource", "UDP transport receive"),
]


def short(sym):
    """A C++ name without namespaces, arguments and template arguments."""
    sym = re.sub(r"\(.*$", "", sym)
    while re.search(r"<[^<>]*>", sym):
        sym = re.sub(r"<[^<>]*>", "", sym)
    return "::".join(sym.split("::")[-2:])


def samples(stream):
    tid, frames = None, []
    for line in stream:
        line = line.rstrip("\n")
        if not line.strip():
            if tid is not None:
                yield tid, frames
            tid, frames = None, []
        elif HEADER.match(line):  # the sample's TID, right-aligned (a frame line starts with its address)
            if tid is not None:
                yield tid, frames
            tid, frames = line.split()[0], []
        else:
            parts = line.split(None, 1)
            rest = parts[1] if len(parts) > 1 else "[unknown]"
            m = re.match(r"^(.*) \(([^()]*)\)$", rest)
            sym, dso = (m.group(1), m.group(2)) if m else (rest, "")
            frames.append((sym, dso))
    if tid is not None:
        yield tid, frames


def category(frames):
    if not frames:
        return "unknown"
    if frames[0][1] != "[kernel.kallsyms]":
        # An inlined frame names no library: the first frame that does is where the code lives.
        dso = next((d for _, d in frames if d not in ("inlined", "")), "").rsplit("/", 1)[-1]
        return "user: " + (re.sub(r"\.so[.\d]*$", "", dso) or "unknown")
    for sym, _ in frames:
        for key, name in KERNEL_PATHS:
            if key in sym:
                return "kernel: " + name
    for sym, _ in frames:
        m = SYSCALL.match(sym)
        if m:
            return "kernel: system call " + m.group(1)
    return "kernel: other"


def main():
    ap = argparse.ArgumentParser()
    ap.add_argument("--names", default="", help="TID=NAME,... (the threads' names)")
    ap.add_argument("--events", type=float, default=0, help="events forwarded over the recording")
    ap.add_argument("--freq", type=float, default=1999, help="perf record's sampling frequency (-F)")
    ap.add_argument("--min-share", type=float, default=3.0)
    ap.add_argument("--top", type=int, default=6)
    args = ap.parse_args()
    names = dict(kv.split("=", 1) for kv in args.names.split(",") if "=" in kv)
    per_thread = collections.Counter()
    cats = collections.defaultdict(collections.Counter)
    leaves = collections.defaultdict(collections.Counter)
    all_cats = collections.Counter()
    roles = collections.defaultdict(collections.Counter)
    sites = collections.defaultdict(collections.Counter)
    for tid, frames in samples(sys.stdin):
        per_thread[tid] += 1
        c = category(frames)
        cats[tid][c] += 1
        all_cats[c] += 1
        leaf = frames[0][0] if frames else "[unknown]"
        leaves[tid][leaf[:90]] += 1
        if c in WAKE_OR_SLEEP:
            user = [sym for sym, dso in frames if dso != "[kernel.kallsyms]" and sym != "[unknown]"]
            site = next((sym for sym in user if CODE.search(sym)),
                        next((sym for sym in user if not sym.startswith("__futex")), "[unknown]"))
            sites[tid][(c, short(site))] += 1
        seen = {name for key, name in ROLES if any(key in sym for sym, _ in frames)}
        for name in seen:
            roles[tid][name] += 1
    total = sum(per_thread.values())
    if total == 0:
        print("  no samples")
        return
    cpu_s = total / args.freq
    per_event = f", {cpu_s * 1e6 / args.events:.1f} us per forwarded event" if args.events > 0 else ""
    print(f"  {total} samples at {args.freq:g} Hz ({cpu_s:.2f} s of CPU{per_event}); what they were doing (all threads):")
    for c, n in all_cats.most_common(10):
        print(f"    {100 * n / total:5.1f}%  {c}")
    for tid, n in per_thread.most_common():
        if 100 * n / total < args.min_share:
            break
        print(f"  thread {names.get(tid, '?')} (tid {tid}): {100 * n / total:.1f}% of the samples")
        if roles[tid]:
            print("    in its stacks: " + "; ".join(f"{r} ({k})" for r, k in roles[tid].most_common(3)))
        for c, k in cats[tid].most_common(6):
            print(f"    {100 * k / n:5.1f}%  {c}")
        for c, verb in zip(WAKE_OR_SLEEP, ("wakes another thread from", "sleeps in", "preempted on leaving the kernel in")):
            top = [(site, k) for (cat, site), k in sites[tid].most_common() if cat == c][:3]
            if top:
                print(f"    {verb}: " + "; ".join(f"{site} ({100 * k / n:.0f}%)" for site, k in top))
        print("    hottest leaf symbols: " + "; ".join(
            f"{sym} {100 * k / n:.0f}%" for sym, k in leaves[tid].most_common(args.top)))


if __name__ == "__main__":
    main()
