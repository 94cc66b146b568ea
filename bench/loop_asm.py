"""Static assembly figures of a kernel's batch loop: instructions, stack spills
and reloads, gathers and permutes between a loop's head and its backward branch.

    python3 bench/loop_asm.py OBJECT PATTERN [PATTERN ...]

OBJECT is a compiled kernel file (e.g. build/bench/CMakeFiles/
principled_brdf_kernels.dir/cpp/src/kernel_avx512.cpp.o); each PATTERN is a
regular expression matched against the demangled names of its functions
(the first match is taken). The loop reported is the largest range of a
backward conditional branch before the function's first return: the batch
loop of an eval or sample loop (its out-of-line blocks, e.g. a lobe that no
lane of a batch has, are not counted).
Counts are static (both sides of a skipped lobe's branch count), the same
measure before and after a change.
"""
import re
import subprocess
import sys


def functions(obj):
    """{demangled name: mangled name} of the object's defined functions"""
    out = subprocess.run(["nm", "--defined-only", obj], capture_output=True, text=True, check=True).stdout
    mangled = [line.split()[-1] for line in out.splitlines() if line.split()[1] in "TtWw"]
    demangled = subprocess.run(["c++filt"], input="\n".join(mangled), capture_output=True, text=True, check=True).stdout
    return dict(zip(demangled.splitlines(), mangled))


def disassemble(obj, mangled):
    out = subprocess.run(["objdump", "-d", "--no-show-raw-insn", "-r", f"--disassemble={mangled}", obj],
                         capture_output=True, text=True, check=True).stdout
    body = []
    for line in out.splitlines():
        m = re.match(r"\s+([0-9a-f]+):\s+(\S+)\s*(.*)", line)
        if m:
            body.append((int(m.group(1), 16), m.group(2), m.group(3)))
    return body


def loop_figures(body):
    # the loop closes with a conditional branch in the function's main body (before
    # its first return: the cold blocks after it jump back into the set-up code)
    first_return = next(address for address, op, _ in body if op.startswith("ret"))
    loops = []
    for address, op, operands in body:
        if op.startswith("j") and op != "jmp" and address < first_return:
            target = re.match(r"([0-9a-f]+)", operands)
            if target and int(target.group(1), 16) < address:
                loops.append((int(target.group(1), 16), address))
    head, branch = max(loops, key=lambda loop: loop[1] - loop[0])
    inside = [(op, operands) for address, op, operands in body if head <= address <= branch]
    stack = [(op, operands) for op, operands in inside if "(%rsp)" in operands or "(%rbp)" in operands]
    vector_stack = [(op, o) for op, o in stack if re.search(r"%[xyz]mm", o)]
    spills = sum(1 for op, o in vector_stack if re.search(r"%[xyz]mm\d+,\s*-?(0x)?[0-9a-f]*\(%r[sb]p\)", o))
    return {
        "instructions": len(inside),
        "spills": spills,
        "reloads": len(vector_stack) - spills,
        "gathers": sum(1 for op, _ in inside if "gather" in op),
        "permutes": sum(1 for op, _ in inside if op.startswith("vperm")),
    }


def main():
    obj, patterns = sys.argv[1], sys.argv[2:]
    names = functions(obj)
    for pattern in patterns:
        name = next((n for n in names if re.search(pattern, n)), None)
        if name is None:
            print(f"{pattern}: no function matches")
            continue
        figures = loop_figures(disassemble(obj, names[name]))
        print(f"{pattern}: " + ", ".join(f"{k} {v}" for k, v in figures.items()))


if __name__ == "__main__":
    main()
