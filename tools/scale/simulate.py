#!/usr/bin/env python3
"""People per hour and storage per person for a batch run on N nodes (docs/scale.md).

Reads a measured run folder (`mannequin batch report --run RUN` must have written RUN/report.json):
each step's wall time and the bytes each person's folder holds. Then simulates a day's backlog of
people through N nodes, event by event, with the two shared limits a cluster adds:

- shared storage: every task reads its input and writes its folder through one file system of
  fixed bandwidth, shared equally among the tasks moving data at that moment;
- the scheduler: it starts at most a fixed number of tasks a second, and one array holds at most
  MaxArraySize tasks (Slurm's default 1001; a Kubernetes Indexed Job 100,000 completions), so a
  large backlog is several arrays, each submitted when the one before is all started.

GPU nodes run `train` in the measured GPU time instead (docs/gpu.md), everything else as on a
CPU node. Standard library only: `python3 tools/scale/simulate.py RUN [--gpu-train-s 45.7]
[--input-mb 5] [--storage-gbps 1] [--starts-per-s 20] [--array-max 1001] [--people 10000]`.
"""

import argparse
import heapq
import json
import os


def person_bytes(person_dir):
    total = 0
    for root, _, files in os.walk(person_dir):
        for f in files:
            total += os.path.getsize(os.path.join(root, f))
    return total


def input_bytes(path):
    return os.path.getsize(path) if os.path.isfile(path) else person_bytes(path)


def simulate(people, nodes, task_s, read_b, write_b, storage_bps, starts_per_s, array_max):
    """People per hour in the steady state (between a quarter and three quarters of `people`
    done, past the ramp-up and before the tail). Each task: read its input, compute, write its
    folder. Storage is processor-shared: k tasks moving data each get storage_bps / k."""
    t = 0.0
    free = nodes
    next_start = 0.0  # the scheduler's next free start slot
    started = 0
    array_end = min(array_max, people)  # tasks of the arrays submitted so far
    computing = []  # heap of (end time, id)
    io = {}  # id -> bytes left, for tasks reading or writing
    phase = {}  # id -> "read" | "write"
    done = 0
    finished = []
    while done < people:
        # Start what the scheduler and the free nodes allow, now.
        while free > 0 and started < people and next_start <= t + 1e-12:
            if started >= array_end:  # the next array goes in once this one has all started
                array_end = min(array_end + array_max, people)
            io[started], phase[started] = read_b, "read"
            started += 1
            free -= 1
            next_start = max(next_start, t) + 1.0 / starts_per_s
        # The next event: a compute end, an IO end, or the scheduler's next slot.
        rate = storage_bps / len(io) if io else 0.0
        candidates = []
        if computing:
            candidates.append(computing[0][0])
        if io:
            candidates.append(t + min(io.values()) / rate)
        if free > 0 and started < people:
            candidates.append(max(next_start, t))
        t_next = min(candidates)
        dt = t_next - t
        for k in io:
            io[k] -= rate * dt
        t = t_next
        for k in [k for k, left in io.items() if left <= 1.0]:  # within a byte: float time steps
            del io[k]
            if phase.pop(k) == "read":
                heapq.heappush(computing, (t + task_s, k))
            else:
                done += 1
                free += 1
                finished.append(t)
        while computing and computing[0][0] <= t + 1e-9:
            _, k = heapq.heappop(computing)
            io[k], phase[k] = write_b, "write"
    a, b = finished[people // 4], finished[3 * people // 4]
    return (3 * people // 4 - people // 4) / (b - a) * 3600


def main():
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("run", help="a measured run folder with report.json")
    ap.add_argument("--people", type=int, default=10000, help="the backlog: people a day")
    ap.add_argument("--gpu-train-s", type=float, default=45.7, help="train's time on a GPU node")
    ap.add_argument("--storage-gbps", type=float, default=1.0, help="shared storage, GB/s")
    ap.add_argument("--starts-per-s", type=float, default=20.0, help="tasks the scheduler starts a second")
    ap.add_argument("--array-max", type=int, default=1001, help="tasks in one array (Slurm MaxArraySize)")
    ap.add_argument("--input-mb", type=float, help="each person's input in MB, in place of the measured run's")
    args = ap.parse_args()

    report = json.load(open(os.path.join(args.run, "report.json")))
    plan = json.load(open(os.path.join(args.run, "plan.json")))
    steps = {}
    for p in report["people"]:
        for s in p["steps"]:
            if s["status"] == "done":
                steps.setdefault(s["step"], []).append(s["seconds"])
    mean = {k: sum(v) / len(v) for k, v in steps.items()}
    stored = [person_bytes(os.path.join(args.run, "people", p["id"])) for p in plan["people"]]
    inputs = [input_bytes(p["input"]) for p in plan["people"]]
    write_b, read_b = sum(stored) / len(stored), sum(inputs) / len(inputs)
    if args.input_mb is not None:
        read_b = args.input_mb * 1e6
    cpu_task = sum(mean.values())
    gpu_task = cpu_task - mean.get("train", 0.0) + args.gpu_train_s
    print(f"measured over {len(stored)} people: " + ", ".join(f"{k} {v:.1f} s" for k, v in mean.items()))
    print(f"per person: task {cpu_task:.1f} s on a CPU node, {gpu_task:.1f} s on a GPU node; "
          f"reads {read_b / 1e6:.1f} MB, stores {write_b / 1e6:.1f} MB")
    print(f"limits: storage {args.storage_gbps} GB/s, {args.starts_per_s:g} starts/s, arrays of {args.array_max}")
    bps = args.storage_gbps * 1e9
    storage_cap = bps / (read_b + write_b) * 3600
    sched_cap = args.starts_per_s * 3600
    print(f"ceilings: storage {storage_cap:,.0f} people/hour, scheduler {sched_cap:,.0f} people/hour")
    print(f"{'nodes':>6} {'CPU people/h':>13} {'GPU people/h':>13}  bound (GPU)")
    for n in [1, 2, 4, 8, 16, 32, 64, 128, 256, 512, 1024, 2048, 4096]:
        people = max(args.people, 8 * n)
        row = [simulate(people, n, task_s, read_b, write_b, bps, args.starts_per_s, args.array_max)
               for task_s in (cpu_task, gpu_task)]
        compute_cap = n * 3600 / gpu_task
        bound = min((compute_cap, "nodes"), (storage_cap, "storage"), (sched_cap, "scheduler"))[1]
        print(f"{n:>6} {row[0]:>13,.0f} {row[1]:>13,.0f}  {bound}")
    print(f"storage per person: {write_b / 1e6:.1f} MB, so {args.people} people a day keep "
          f"{args.people * write_b / 1e12:.2f} TB a day")


if __name__ == "__main__":
    main()
