#!/usr/bin/env python3
"""A second, independent implementation of the wire format (Python: protobuf + pyzmq + numpy)
talks to the C++ loopback server and decodes the C++ golden files.

usage: python_client_test.py PROTOC PROTO_DIR GOLDEN_DIR LOOPBACK_BINARY
Checks: every golden v1.0 to v1.6 file decodes with Python's protobuf and has the type its name says;
the golden GasFields arrays hold 0.25 (f+1) + 0.125 i; over tcp loopback a Python DEALER
handshakes, configures a 4x3x2 grid, sends GasFields built from numpy arrays and receives
Sources (eps_g = 1, other sources 0, checksums equal to sequential sums of what was sent);
garbage gets Error MALFORMED_ENVELOPE; Shutdown gets Ack and the server process exits.
"""
import os
import struct
import subprocess
import sys
import tempfile
import time

import numpy as np
import zmq


def read_cdmf(path):
    data = open(path, "rb").read()
    assert data[:4] == b"CDMF", path
    version, count = struct.unpack_from("<II", data, 4)
    assert version == 1
    pos, frames = 12, []
    for _ in range(count):
        (length,) = struct.unpack_from("<Q", data, pos)
        pos += 8
        frames.append(data[pos:pos + length])
        pos += length
    assert pos == len(data), "trailing bytes in " + path
    return frames


def main():
    protoc, proto_dir, golden_dir, loopback = sys.argv[1:5]
    with tempfile.TemporaryDirectory() as tmp:
        subprocess.run([protoc, "--python_out", tmp, "-I", proto_dir] +
                       [f"coredem/v1/{n}.proto" for n in ("common", "configure", "messages", "envelope")],
                       check=True)
        sys.path.insert(0, tmp)
        from coredem.v1 import envelope_pb2 as pb
        from coredem.v1 import common_pb2 as common

        # --- golden files -------------------------------------------------------------
        for version in ("v1.0", "v1.1"):
            gdir = os.path.join(golden_dir, version)
            names = sorted(f[:-5] for f in os.listdir(gdir) if f.endswith(".cdmf"))
            assert len(names) == 15, names
            for name in names:
                frames = read_cdmf(os.path.join(gdir, name + ".cdmf"))
                env = pb.Envelope()
                env.ParseFromString(frames[0])
                assert common.MessageType.Name(env.type) == "MESSAGE_TYPE_" + name.upper(), name
                assert env.WhichOneof("body") == name, (name, env.WhichOneof("body"))
                assert len(frames) == 1 + len(env.arrays)
                for f, (d, raw) in enumerate(zip(env.arrays, frames[1:])):
                    assert d.byte_length == len(raw)
                    values = np.frombuffer(raw, dtype="<f8")
                    expected = 0.25 * (f + 1) + 0.125 * np.arange(values.size)
                    assert np.array_equal(values, expected), (name, d.name)
            print(f"python: decoded {len(names)} golden {version} files")
        # v1.2: the rank of a decomposed CFD participant and partial GasFields/Sources (an int64
        # cell list, the rank's fluid volumes, one row per listed cell), read by Python's protobuf.
        gdir = os.path.join(golden_dir, "v1.2")
        names = sorted(f[:-5] for f in os.listdir(gdir) if f.endswith(".cdmf"))
        assert len(names) == 15, names
        for name in names:
            frames = read_cdmf(os.path.join(gdir, name + ".cdmf"))
            env = pb.Envelope()
            env.ParseFromString(frames[0])
            assert env.WhichOneof("body") == name, (name, env.WhichOneof("body"))
            if name == "hello":
                assert (env.hello.protocol_minor, env.hello.rank, env.hello.rank_count) == (2, 1, 2)
            if name in ("gas_fields", "sources"):
                body = getattr(env, name)
                assert body.partial and body.touched_count == 1, body
                arrays = {d.name: (d, raw) for d, raw in zip(env.arrays, frames[1:])}
                d, raw = arrays["cells"]
                assert d.dtype == common.DTYPE_INT64
                assert np.frombuffer(raw, dtype="<i8").tolist() == [1]
                if name == "gas_fields":
                    assert np.frombuffer(arrays["fluid_volume"][1], dtype="<f8").tolist() == [0.125]
                    assert np.frombuffer(arrays["T_g"][1], dtype="<f8").tolist() == [0.75]
                else:
                    assert np.frombuffer(arrays["eps_g"][1], dtype="<f8").tolist() == [0.25]
        print(f"python: decoded {len(names)} golden v1.2 files")
        # v1.3: the partial Sources also carry Q_rad (float64, one row per listed cell).
        frames = read_cdmf(os.path.join(golden_dir, "v1.3", "sources.cdmf"))
        env = pb.Envelope()
        env.ParseFromString(frames[0])
        assert env.WhichOneof("body") == "sources"
        arrays = {d.name: (d, raw) for d, raw in zip(env.arrays, frames[1:])}
        d, raw = arrays["Q_rad"]
        assert d.dtype == common.DTYPE_FLOAT64 and list(d.shape) == [1], d
        assert np.frombuffer(raw, dtype="<f8").tolist() == [2.0]
        hello = pb.Envelope()
        hello.ParseFromString(read_cdmf(os.path.join(golden_dir, "v1.3", "hello.cdmf"))[0])
        assert hello.hello.protocol_minor == 3
        print("python: decoded the golden v1.3 Sources with Q_rad")
        # v1.5: the partial GasFields also carry Q_split [1], the partial Sources mom_p [1, 3].
        for name, array, shape, values in (("gas_fields", "Q_split", [1], [-2.25]),
                                           ("sources", "mom_p", [1, 3], [2.25, 2.375, 2.5])):
            frames = read_cdmf(os.path.join(golden_dir, "v1.5", name + ".cdmf"))
            env = pb.Envelope()
            env.ParseFromString(frames[0])
            assert env.WhichOneof("body") == name
            arrays = {d.name: (d, raw) for d, raw in zip(env.arrays, frames[1:])}
            d, raw = arrays[array]
            assert d.dtype == common.DTYPE_FLOAT64 and list(d.shape) == shape, d
            assert np.frombuffer(raw, dtype="<f8").tolist() == values
        hello = pb.Envelope()
        hello.ParseFromString(read_cdmf(os.path.join(golden_dir, "v1.5", "hello.cdmf"))[0])
        assert hello.hello.protocol_minor == 5
        print("python: decoded the golden v1.5 GasFields with Q_split and Sources with mom_p")
        # v1.6 Configure: Hertz-Mindlin properties, a material pair, wall materials.
        env = pb.Envelope()
        env.ParseFromString(read_cdmf(os.path.join(golden_dir, "v1.6", "configure.cdmf"))[0])
        c = env.configure
        assert c.materials[0].youngs_modulus == 1.5e8 and c.materials[0].poisson_ratio == 0.25
        assert not c.materials[1].HasField("poisson_ratio")
        p = c.material_pairs[0]
        assert (p.material_a, p.material_b, p.e_n) == (1, 2, 0.5) and not p.HasField("friction")
        assert c.walls.box.material_id == 2 and c.walls.planes[0].material_id == 1
        assert c.walls.revolved[0].material_id == 2 and not c.walls.revolved[1].HasField("material_id")
        assert c.walls.meshes[0].material_id == 1
        print("python: decoded the golden v1.6 Configure with contact materials")
        # v1.1 Configure: explicit positions and chemistry, read by Python's protobuf.
        env = pb.Envelope()
        env.ParseFromString(read_cdmf(os.path.join(golden_dir, "v1.1", "configure.cdmf"))[0])
        c = env.configure
        assert [s.name for s in c.solid_species] == ["Fe2O3", "Fe3O4", "Al2O3"], c.solid_species
        assert c.particle_sets[1].positions[1].x == -0.25
        r = c.reactions[0]
        assert [(t.species, t.nu) for t in r.terms] == [("Fe3O4", -4.0), ("O2", -1.0), ("Fe2O3", 6.0)]
        assert r.rate.activation_energy == 8.0e4 and r.heat_of_reaction == -4.75e5
        assert c.chemistry.clg.oc_reduction and c.chemistry.clg.wgs
        assert c.chemistry.removal_fraction == 0.125 and not c.chemistry.reaction_heat

        # --- live exchange with the C++ loopback server ---------------------------------
        ep_file = os.path.join(tmp, "endpoint")
        server = subprocess.Popen([loopback, "serve", "--endpoint", "tcp://127.0.0.1:*",
                                   "--endpoint-file", ep_file, "--idle-limit", "60"])
        try:
            for _ in range(200):
                if os.path.exists(ep_file) and os.path.getsize(ep_file) > 0:
                    break
                time.sleep(0.05)
            endpoint = open(ep_file).read().strip()
            ctx = zmq.Context()
            sock = ctx.socket(zmq.DEALER)
            sock.setsockopt(zmq.LINGER, 1000)
            sock.connect(endpoint)
            seq = [0]

            def request(env, arrays=(), raw=None):
                if raw is None:
                    seq[0] += 1
                    env.sequence = seq[0]
                    frames = [env.SerializeToString()] + [a.tobytes() for a in arrays]
                else:
                    frames = raw
                sock.send_multipart(frames)
                if not sock.poll(10000):
                    raise RuntimeError("no reply from " + endpoint)
                reply = sock.recv_multipart()
                out = pb.Envelope()
                out.ParseFromString(reply[0])
                return out, reply[1:]

            hello = pb.Envelope(type=common.MESSAGE_TYPE_HELLO)
            hello.hello.protocol_major = 1
            hello.hello.protocol_minor = 7
            hello.hello.software_version = "python-test"
            hello.hello.role = common.ROLE_CFD
            welcome, _ = request(hello)
            assert welcome.type == common.MESSAGE_TYPE_WELCOME
            assert welcome.welcome.protocol_minor == 6  # min(server 1.6, client 1.7)
            session = welcome.welcome.session_id

            nx, ny, nz, ns = 4, 3, 2, 2
            n = nx * ny * nz
            cfg = pb.Envelope(type=common.MESSAGE_TYPE_CONFIGURE, session_id=session)
            grid = cfg.configure.coupling_mesh.cartesian
            grid.spacing.x = grid.spacing.y = grid.spacing.z = 0.01
            grid.counts.x, grid.counts.y, grid.counts.z = nx, ny, nz
            for name, mm in (("O2", 0.032), ("N2", 0.028)):
                s = cfg.configure.species.add()
                s.name, s.molar_mass = name, mm
            cfg.configure.sub_cycling.dt_cfd = 1e-3
            cfg.configure.sub_cycling.n_sub = 4
            cfg.configure.sub_cycling.dt_dem = 2.5e-4
            configured, _ = request(cfg)
            assert configured.type == common.MESSAGE_TYPE_CONFIGURED, configured
            assert configured.configured.cell_count == n

            fields = [("u_g", 3), ("grad_p", 3), ("T_g", 1), ("rho_g", 1), ("mu_g", 1),
                      ("kappa_g", 1), ("cp_g", 1), ("Y_g", ns)]
            gas = pb.Envelope(type=common.MESSAGE_TYPE_GAS_FIELDS, session_id=session, step=0)
            gas.gas_fields.dt = 1e-3
            gas.gas_fields.cell_count = n
            gas.gas_fields.species_count = ns
            arrays = []
            for f, (name, comps) in enumerate(fields):
                a = (1.0 + f + 0.01 * np.arange(n * comps, dtype="<f8")).reshape(
                    (n, comps) if comps > 1 else (n,))
                d = gas.arrays.add()
                d.name, d.dtype = name, common.DTYPE_FLOAT64
                d.shape.extend(a.shape)
                d.byte_length = a.nbytes
                arrays.append(a)
            sources, frames = request(gas, arrays)
            assert sources.type == common.MESSAGE_TYPE_SOURCES, sources
            got = {d.name: np.frombuffer(raw, dtype="<f8") for d, raw in zip(sources.arrays, frames)}
            assert np.all(got["eps_g"] == 1.0)
            for name in ("K_sl", "K_sl_Us", "H", "H_Tp", "R_species", "Q_hom"):
                assert np.all(got[name] == 0.0), name
            assert got["R_species"].size == n * ns
            for f, a in enumerate(arrays):
                total = 0.0
                for v in a.ravel():  # the server sums sequentially: same order, same result
                    total += float(v)
                assert got["checksum"][f] == total, (fields[f][0], got["checksum"][f], total)

            err, _ = request(None, raw=[b"\xff\xfe garbage \x00"])
            assert err.type == common.MESSAGE_TYPE_ERROR
            assert err.error.code == common.ERROR_CODE_MALFORMED_ENVELOPE, err

            bye = pb.Envelope(type=common.MESSAGE_TYPE_SHUTDOWN, session_id=session)
            bye.shutdown.reason = "python test done"
            ack, _ = request(bye)
            assert ack.type == common.MESSAGE_TYPE_ACK
            sock.close()
            ctx.term()
            assert server.wait(timeout=10) == 0
            print("python: exchange with the C++ loopback server ok")
        finally:
            if server.poll() is None:
                server.kill()
                server.wait()


if __name__ == "__main__":
    main()
