#!/usr/bin/python3
"""config/fieldguard.dbc read by an independent DBC library (Debian's python3-canmatrix), decoding a replay's
candump log, held against the obstacles JSONL of the same replay: each frame's FG_OBSTACLE_SUMMARY (frame counter,
count, nearest distance or NO_OBSTACLE) and its FG_OBSTACLE messages, which the DBC multiplexes on Index
(XMin_0 is the nearest obstacle's).

    dbc_canmatrix.py DBC CANDUMP_LOG OBSTACLES_JSONL

Prints one JSON summary line; exits 1 on any mismatch."""
import json
import sys
import warnings

warnings.filterwarnings("ignore")
import canmatrix.formats  # noqa: E402


def main():
    dbc, log, jsonl = sys.argv[1:4]
    db = canmatrix.formats.loadp_flat(dbc)
    by_id = {f.arbitration_id.id: f for f in db.frames}
    frames = {}
    for line in open(jsonl):
        j = json.loads(line)
        frames[j["frame"] % 65536] = j
    errors, summaries, obstacles, current = [], 0, 0, None
    for line in open(log):
        _, _, frame = line.split()
        can_id, data = frame.split("#")
        f = by_id.get(int(can_id, 16))
        if f is None:
            continue
        d = {k: v for k, v in f.decode(bytes.fromhex(data)).items()}
        if f.name == "FG_OBSTACLE_SUMMARY":
            summaries += 1
            current = frames.get(int(d["FrameCounter"].raw_value))
            if current is None:
                errors.append(f"summary of frame {d['FrameCounter'].raw_value}: not in the JSONL")
                continue
            n = len(current["obstacles"])
            if int(d["ObstacleCount"].raw_value) != min(n, 250):
                errors.append(f"frame {current['frame']}: count {d['ObstacleCount'].raw_value}, JSONL {n}")
            nearest = d["NearestDistance"]
            if n == 0 and nearest.raw_value != 65535:
                errors.append(f"frame {current['frame']}: no obstacle but NearestDistance raw {nearest.raw_value}")
            if n == 0 and str(nearest.named_value) != "NO_OBSTACLE":
                errors.append(f"frame {current['frame']}: raw 65535 not named NO_OBSTACLE ({nearest.named_value})")
            if n > 0 and abs(float(nearest.phys_value) - min(current["obstacles"][0]["distance"], 600)) > 0.006:
                errors.append(f"frame {current['frame']}: nearest {nearest.phys_value}, JSONL "
                              f"{current['obstacles'][0]['distance']}")
        elif f.name == "FG_OBSTACLE" and current is not None:
            obstacles += 1
            i = int(d["Index"].raw_value)
            names = set(d)
            others = [k for k in names if "_" in k and k.rsplit("_", 1)[1] != str(i)]
            if f"XMin_{i}" not in names or others:
                errors.append(f"frame {current['frame']} obstacle {i}: decoded {sorted(names)}")
                continue
            o = current["obstacles"][i]
            for key, value in ((f"XMin_{i}", o["min"][0]), (f"XMax_{i}", o["max"][0]), (f"YMin_{i}", o["min"][1]),
                               (f"YMax_{i}", o["max"][1])):
                want = max(-102.4, min(102.3, value))
                if abs(float(d[key].phys_value) - want) > 0.051:
                    errors.append(f"frame {current['frame']} obstacle {i}: {key} {d[key].phys_value}, JSONL {value}")
            size = "small" if int(d[f"SizeClass_{i}"].raw_value) == 0 else "large"
            if size != o["class"]:
                errors.append(f"frame {current['frame']} obstacle {i}: class {size}, JSONL {o['class']}")
    print(json.dumps({"summaries": summaries, "obstacles": obstacles, "errors": errors[:20],
                      "error_count": len(errors)}))
    sys.exit(1 if errors or summaries == 0 else 0)


if __name__ == "__main__":
    main()
