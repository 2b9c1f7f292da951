#!/usr/bin/env python3
"""A closed 6 x 3 x 6 m room (rho 0.7) lit by a one-sided 1 x 1 m lamp 0.1 m below its ceiling,
with N grey boxes (rho 0.5) of random size (0.1-0.8 m) and rotation that may touch and cross.

    random_boxes_room.py N SEED [through] OUT.json

`through`: boxes may also pass through the walls, floor and ceiling.
Same N, SEED and flag: the same scene (Python's random module).
"""
import json
import random
import sys

n, seed = int(sys.argv[1]), int(sys.argv[2])
through = len(sys.argv) > 4 and sys.argv[3] == "through"
out = sys.argv[-1]
random.seed(seed)
objects = [
    {"type": "box", "material": "wall", "inward": True, "transform": {"scale": [6, 3, 6], "translate": [0, 1.5, 0]}},
    {"type": "quad", "material": "lamp",
     "transform": {"scale": 1, "rotate": {"axis": [1, 0, 0], "degrees": 90}, "translate": [0, 2.9, 0]}},
]
for k in range(n):
    size = [random.uniform(0.1, 0.8) for _ in range(3)]
    if through:
        at = [random.uniform(-3.2, 3.2), random.uniform(-0.2, 3.2), random.uniform(-3.2, 3.2)]
    else:
        at = [random.uniform(-2.5, 2.5), random.uniform(0.3, 2.4), random.uniform(-2.5, 2.5)]
    axis = [random.uniform(-1, 1) for _ in range(3)]
    objects.append({"type": "box", "material": "grey", "transform": {
        "scale": size, "rotate": {"axis": axis, "degrees": random.uniform(0, 90)}, "translate": at}})
materials = {"wall": {"reflectance": 0.7}, "grey": {"reflectance": 0.5}, "lamp": {"reflectance": 0, "emission": 10}}
with open(out, "w") as f:
    json.dump({"name": f"room {n} boxes", "materials": materials, "objects": objects}, f, indent=0)
