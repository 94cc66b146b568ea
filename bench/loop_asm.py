"""Static assembly figures of a kernel's batch loop: instructions, stack spills
and reloads, gathers and permutes in the loop's blocks.

    python3 bench/loop_asm.py OBJECT PATTERN [PATTERN ...]

OBJECT is a compiled kernel file (e.g. build/bench/CMakeFiles/
principled_brdf_kernels.dir/cpp/src/kernel_avx512.cpp.o); each PATTERN is a
regular expression matched against the demangled names of its functions
(the first match is taken). The loop reported is the function's largest
natural loop (the blocks that reach a back edge's source without passing its
target, which dominates it), wherever the compiler placed those blocks: the
loop of an eval loop (two batches a step for a uniform material, one for
per-element materials), the pipelined loop (three batches) of a sample loop.
Counts are static: every block counts once, both sides of a skipped lobe's
branch included, the same measure before and after a change.
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
        # relocation lines ("R_X86_64_PC32 .LC3-0x4") annotate the instruction above them
        if m and not m.group(2).startswith("R_"):
            body.append((int(m.group(1), 16), m.group(2), m.group(3)))
    return body


def blocks_of(body):
    """The basic blocks, as lists of (address, op, operands), and each block's successors (block indices)."""
    addresses = {address for address, _, _ in body}
    leaders = {body[0][0]}
    for k, (address, op, operands) in enumerate(body):
        if op.startswith("j") or op.startswith("ret") or op == "notrack":
            target = re.match(r"([0-9a-f]+) <", operands)
            if target and int(target.group(1), 16) in addresses:
                leaders.add(int(target.group(1), 16))
            if k + 1 < len(body):
                leaders.add(body[k + 1][0])
    blocks, index_of = [], {}
    for instruction in body:
        if instruction[0] in leaders:
            index_of[instruction[0]] = len(blocks)
            blocks.append([])
        blocks[-1].append(instruction)
    successors = []
    for b, block in enumerate(blocks):
        _, op, operands = block[-1]
        target = re.match(r"([0-9a-f]+) <", operands)
        # (an indirect jump, e.g. through a switch's table, leaves no edge here)
        jumped = [index_of[int(target.group(1), 16)]] if target and int(target.group(1), 16) in index_of else []
        following = [b + 1] if b + 1 < len(blocks) else []
        if op.startswith("ret") or op.startswith("ud2"):
            successors.append([])
        elif op.startswith("jmp") or op == "notrack":
            successors.append(jumped)
        elif op.startswith("j"):
            successors.append(jumped + following)
        else:
            successors.append(following)
    return blocks, successors


def dominators(successors):
    """dominators[b]: the blocks every path from the entry to b passes through
    (blocks the entry does not reach, e.g. behind a switch's table, are left out)"""
    count = len(successors)
    reached, stack = {0}, [0]
    while stack:
        for t in successors[stack.pop()]:
            if t not in reached:
                reached.add(t)
                stack.append(t)
    predecessors = [[] for _ in range(count)]
    for b in reached:
        for t in successors[b]:
            predecessors[t].append(b)
    dom = [set(reached) for _ in range(count)]
    dom[0] = {0}
    changed = True
    while changed:
        changed = False
        for b in sorted(reached - {0}):
            new = set.intersection(*[dom[p] for p in predecessors[b]]) | {b}
            if new != dom[b]:
                dom[b], changed = new, True
    return dom, predecessors


def natural_loops(successors):
    """{header: the blocks of its natural loop}, the loops of one header merged"""
    dom, predecessors = dominators(successors)
    loops = {}
    for tail, targets in enumerate(successors):
        for header in targets:
            if tail in predecessors[header] and header in dom[tail]:  # a back edge
                # (a one-block loop, tail == header, has no other member)
                members, stack = {header, tail}, [tail] if tail != header else []
                while stack:
                    for p in predecessors[stack.pop()]:
                        if p not in members:
                            members.add(p)
                            stack.append(p)
                loops.setdefault(header, set()).update(members)
    return loops


def loop_figures(body):
    # the batch loop: the natural loop (a back edge's target dominating its source)
    # with the most instructions, wherever the compiler placed its blocks
    blocks, successors = blocks_of(body)
    loops = natural_loops(successors)
    members = max(loops.values(), key=lambda m: sum(len(blocks[b]) for b in m))
    inside = [(op, operands) for b in sorted(members) for _, op, operands in blocks[b]]
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
