"""Data-parallel training helpers (torchrun): process group, device, hand-made gradient averaging.

    torchrun --nproc_per_node 2 -m training.learning.train --model follower

Without torchrun (no WORLD_SIZE, or 1) every helper is a no-op and training runs in one process.
"""
from __future__ import annotations

import os

import torch
import torch.distributed as dist


def setup_distributed(device: str) -> tuple[int, int]:
    """(rank, world size); starts the process group under torchrun."""
    if "WORLD_SIZE" not in os.environ or int(os.environ["WORLD_SIZE"]) == 1:
        return 0, 1
    backend = "nccl" if device.startswith("cuda") else "gloo"
    dist.init_process_group(backend)
    return dist.get_rank(), dist.get_world_size()


def wait_for_all(world: int) -> None:
    """Every process waits here until all have arrived. After training, rank 0 alone still plots
    and writes the run's files: a process that tore the group down meanwhile died at exit
    ("terminate called without an active exception", in the two-process test)."""
    if world > 1:
        dist.barrier()


def stop_distributed(world: int) -> None:
    if world > 1:
        dist.destroy_process_group()


def pick_device(name: str) -> str:
    if name == "auto":
        if torch.cuda.is_available():
            return f"cuda:{int(os.environ.get('LOCAL_RANK', 0))}"
        return "cpu"
    return name


def average_gradients(modules, world: int):
    """All-reduce gradients by hand: the GAN's alternating updates touch different modules per
    step, which DistributedDataParallel's single-backward assumption does not fit."""
    if world == 1:
        return
    for m in modules:
        for p in m.parameters():
            if p.grad is not None:
                dist.all_reduce(p.grad)
                p.grad /= world


def broadcast_parameters(modules, world: int):
    if world == 1:
        return
    for m in modules:
        for p in m.state_dict().values():
            dist.broadcast(p, 0)
