"""A v1.1 orchestrator refuses a chemistry case when the DEM server speaks protocol 1.0.

Starts `coredem-loopback serve --protocol-minor 0` (a v1.0 peer on an ephemeral port), points a
chemistry case at it with dem.endpoint, runs `coredem run`, and expects a non-zero exit with a
message that names both versions. Usage: old_server_test.py COREDEM COREDEM_LOOPBACK
"""
import os
import subprocess
import sys
import tempfile
import time

coredem, loopback = sys.argv[1], sys.argv[2]
with tempfile.TemporaryDirectory() as tmp:
    ep_file = os.path.join(tmp, "endpoint")
    server = subprocess.Popen([loopback, "serve", "--endpoint", "tcp://127.0.0.1:*",
                               "--endpoint-file", ep_file, "--idle-limit", "30",
                               "--protocol-minor", "0"],
                              stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    try:
        deadline = time.time() + 20
        while not os.path.exists(ep_file):
            if time.time() > deadline:
                raise SystemExit("the loopback server wrote no endpoint within 20 s")
            time.sleep(0.05)
        endpoint = open(ep_file).read().strip()
        case = os.path.join(tmp, "case")
        os.makedirs(case)
        with open(os.path.join(case, "case.yaml"), "w") as f:
            f.write(f"""name: old-server
time: {{end: 0.02, dt: 0.01}}
grid: {{spacing: [0.01, 0.01, 0.01], cells: [1, 1, 1]}}
gravity: [0, 0, 0]
species: [{{name: A, molar_mass: 0.025}}]
solid_species: [{{name: B, molar_mass: 0.025}}]
materials: [{{name: s, density: 2500, k_n: 1000, e_n: 0.9}}]
particles: [{{material: s, diameter: 0.003, composition: {{B: 1.0}}, positions: [[0.005, 0.005, 0.005]]}}]
reactions:
  - name: r
    terms: [{{species: B, nu: -1}}, {{species: A, nu: 1}}]
    rate: {{law: constant, A: 1.0e-6}}
dem: {{endpoint: "{endpoint}", timeout_s: 10}}
gas: {{u_g: [0, 0, 0], T_g: 300, Y_g: {{A: 1.0}}}}
""")
        run = subprocess.run([coredem, "run", case, "--out", os.path.join(tmp, "run"), "--no-plots"],
                             capture_output=True, text=True, timeout=60)
        out = run.stdout + run.stderr
        assert run.returncode != 0, "coredem run succeeded against a v1.0 server:\n" + out
        assert "speaks protocol 1.0" in out and "needs protocol 1.1" in out, out
        print("refused as expected:", [l for l in out.splitlines() if "needs protocol 1.1" in l][0])
    finally:
        server.terminate()
        server.wait(timeout=10)
