#!/usr/bin/python3
"""mdwe_exec.py CMD [ARGS...]: runs CMD under the seccomp filter systemd installs for
MemoryDenyWriteExecute=yes with SystemCallArchitectures=native (systemd.exec(5)), so that a test
sees what a unit with those settings lets a program do without a service manager:

  mmap with PROT_WRITE and PROT_EXEC           -> EPERM
  mprotect, pkey_mprotect with PROT_EXEC       -> EPERM (a mapping never becomes executable later)
  shmat with SHM_EXEC                          -> EPERM
  a system call of another ABI than x86-64     -> the process is killed

x86-64 only (the numbers below are its system calls). Exit 70 when the filter cannot be installed.
"""
import ctypes
import os
import struct
import sys

PR_SET_NO_NEW_PRIVS, PR_SET_SECCOMP, SECCOMP_MODE_FILTER = 38, 22, 2
AUDIT_ARCH_X86_64 = 0xC000003E
NR_MMAP, NR_MPROTECT, NR_SHMAT, NR_PKEY_MPROTECT = 9, 10, 30, 329
PROT_WRITE, PROT_EXEC, SHM_EXEC = 0x2, 0x4, 0o100000
RET_ALLOW, RET_EPERM, RET_KILL_PROCESS = 0x7FFF0000, 0x00050000 | 1, 0x80000000
BPF_LD_W_ABS, BPF_JEQ_K, BPF_JSET_K, BPF_RET_K = 0x20, 0x15, 0x45, 0x06
# struct seccomp_data: nr (u32), arch (u32), instruction_pointer (u64), args[6] (u64 each); the
# flags are the low 32 bits of the third argument (little endian).
NR, ARCH, THIRD_ARGUMENT = 0, 4, 16 + 8 * 2


def assemble(lines):
    """Classic BPF from (op, k, jump_if_true, jump_if_false) tuples and ("label", NAME) lines."""
    where, code = {}, []
    for line in lines:
        if line[0] == "label":
            where[line[1]] = len(code)
        else:
            code.append(line)

    def offset(target, at):
        return 0 if target is None else where[target] - at - 1

    return b"".join(struct.pack("HBBI", op, offset(yes, at), offset(no, at), k)
                    for at, (op, k, yes, no) in enumerate(code))


PROGRAM = assemble([
    (BPF_LD_W_ABS, ARCH, None, None),
    (BPF_JEQ_K, AUDIT_ARCH_X86_64, "native", "foreign"),
    ("label", "foreign"), (BPF_RET_K, RET_KILL_PROCESS, None, None),
    ("label", "native"), (BPF_LD_W_ABS, NR, None, None),
    (BPF_JEQ_K, NR_MMAP, "mmap", "not_mmap"), ("label", "not_mmap"),
    (BPF_JEQ_K, NR_MPROTECT, "mprotect", "not_mprotect"), ("label", "not_mprotect"),
    (BPF_JEQ_K, NR_PKEY_MPROTECT, "mprotect", "not_pkey_mprotect"), ("label", "not_pkey_mprotect"),
    (BPF_JEQ_K, NR_SHMAT, "shmat", "allow"),
    ("label", "mmap"), (BPF_LD_W_ABS, THIRD_ARGUMENT, None, None),
    (BPF_JSET_K, PROT_WRITE, "mmap_writable", "allow"),
    ("label", "mmap_writable"), (BPF_JSET_K, PROT_EXEC, "deny", "allow"),
    ("label", "mprotect"), (BPF_LD_W_ABS, THIRD_ARGUMENT, None, None),
    (BPF_JSET_K, PROT_EXEC, "deny", "allow"),
    ("label", "shmat"), (BPF_LD_W_ABS, THIRD_ARGUMENT, None, None),
    (BPF_JSET_K, SHM_EXEC, "deny", "allow"),
    ("label", "deny"), (BPF_RET_K, RET_EPERM, None, None),
    ("label", "allow"), (BPF_RET_K, RET_ALLOW, None, None),
])


class SockFprog(ctypes.Structure):
    _fields_ = [("len", ctypes.c_ushort), ("filter", ctypes.c_char_p)]


def main():
    if len(sys.argv) < 2:
        sys.exit("usage: mdwe_exec.py CMD [ARGS...]")
    libc = ctypes.CDLL(None, use_errno=True)
    libc.prctl.argtypes = [ctypes.c_int, ctypes.c_ulong, ctypes.c_void_p, ctypes.c_ulong, ctypes.c_ulong]
    program = SockFprog(len(PROGRAM) // 8, PROGRAM)
    if libc.prctl(PR_SET_NO_NEW_PRIVS, 1, None, 0, 0) != 0 or \
            libc.prctl(PR_SET_SECCOMP, SECCOMP_MODE_FILTER, ctypes.addressof(program), 0, 0) != 0:
        print(f"mdwe_exec.py: cannot install the filter: {os.strerror(ctypes.get_errno())}", file=sys.stderr)
        sys.exit(70)
    os.execvp(sys.argv[1], sys.argv[1:])


if __name__ == "__main__":
    main()
