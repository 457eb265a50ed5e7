"""A fleet across four hosts at the issue's size (issue 36 item 3): 50 clients x 4 goals a round.

The hosts are network namespaces on a private bridge (bench/fleet_network.py: the server on
host 1, compilation and generation on host 2, synthesis on hosts 3 and 4, clients spread over
all four, DDS discovery on that subnet only). Rounds: none (no fault), then one fault each:
host 3's cable pulled for 5 s, host 4 killed (started again after its round), host 2's nodes
restarted. Each goal is the paper's task (whole pipeline); clients send their goals back to
back. Prints one line per round and writes bench/results/fleet.md.

Needs root and ``ip`` (iproute2).

    .venv/bin/python bench/bench_fleet.py [--clients 50] [--goals 4] [--fault-after 2]
"""

from __future__ import annotations

import argparse
import platform
import sys
import tempfile
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))

from fleet_network import (Fleet, PrivateNetwork, killed_host, network_namespaces_available,
                           pulled_cable, restarted_host, run_round)

RESULTS = Path(__file__).resolve().parent / 'results' / 'fleet.md'
COLUMNS = ('round', 'goals', 'answers', 'duplicates', 'codes', 'median_s', 'max_s', 'wall_s', 'recovery_s',
           'restart_s')


def table(rows: list[dict]) -> str:
    lines = ['| ' + ' | '.join(COLUMNS) + ' |', '|' + '---|' * len(COLUMNS)]
    for row in rows:
        cells = []
        for column in COLUMNS:
            value = row.get(column)
            if column == 'codes':
                value = ', '.join(f'{name} {count}' for name, count in value.items())
            elif column == 'round' and row.get('fault'):
                value = f"{value}: {row['fault']}"
            cells.append('-' if value is None else str(value))
        lines.append('| ' + ' | '.join(cells) + ' |')
    return '\n'.join(lines)


def failure_list(rows: list[dict]) -> str:
    """What the clients were told when a goal did not succeed, per round."""
    lines = [f"- {row['round']}: {count} x {said}" for row in rows for said, count in row['failures'].items()]
    return ('What the other answers said:\n\n' + '\n'.join(lines) + '\n\n') if lines else ''


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument('--clients', type=int, default=50)
    parser.add_argument('--goals', type=int, default=4)
    parser.add_argument('--fault-after', type=float, default=2.0,
                        help='seconds into a round (after every client found the server) when its fault starts')
    args = parser.parse_args(argv)
    if not network_namespaces_available():
        print('bench_fleet: needs root and `ip` (iproute2)', file=sys.stderr)
        return 2
    rows = []
    with tempfile.TemporaryDirectory() as workdir, PrivateNetwork() as network:
        fleet = Fleet(network, Path(workdir))
        started = time.monotonic()
        fleet.start()
        print(f'4 hosts up in {time.monotonic() - started:.1f} s', flush=True)
        rounds = [('none', None), ('cable', pulled_cable(3, 5.0)), ('killed', killed_host(4)),
                  ('restarted', restarted_host(2))]
        for tag, fault in rounds:
            result = run_round(fleet, tag, args.clients, args.goals, interval=0.0, fault=fault,
                               fault_after=args.fault_after)
            row = result.summary()
            row['failures'] = result.failures()
            rows.append(row)
            print(row, flush=True)
            if tag == 'killed':  # the next round starts with both workers again
                fleet.start_host(4)
                fleet.wait_until_up(4)
    exactly_once = all(row['answers'] == row['goals'] and row['duplicates'] == 0 for row in rows)
    text = (f'# A fleet across four hosts (bench/bench_fleet.py)\n\n'
            f'{args.clients} clients x {args.goals} goals a round (the paper\'s task, whole pipeline, goals back '
            f'to back), spread over four network namespaces on a private bridge; a fault {args.fault_after:g} s '
            f'into each round after the first. Machine: {platform.machine()}, 2 cores shared with other '
            f'work; Python {platform.python_version()}.\n\n'
            f'{table(rows)}\n\n'
            f'{failure_list(rows)}'
            f'Every goal answered exactly once: {"yes" if exactly_once else "NO"}. `median_s`/`max_s`: '
            'seconds from sending to the answer of the SUCCESS goals; `wall_s`: the round; `recovery_s`: from '
            "the fault's end (cable back, host killed, restarted host up) to the next SUCCESS (for the cable: "
            "to the cut-off host's clients); `restart_s`: the restarted host's nodes up again.\n")
    RESULTS.write_text(text)
    print(table(rows))
    return 0 if exactly_once else 1


if __name__ == '__main__':
    sys.exit(main())
