"""Generators of the public GR(1) benchmark families, as structuredslugs text (our own writing).

Each family is a function ``size -> text``; ``FAMILIES`` lists the sizes the benchmark runs
(bench/bench_gr1_families.py), smallest first.

- ``amba``: the AMBA AHB arbiter after Bloem, Jobstmann, Piterman, Pnueli, Sa'ar, "Synthesis
  of Reactive(1) designs", JCSS 78(3), 2012, Sect. 7.2 (assumptions A1-A4, guarantees
  G1-G11, with the monitor variables stateA1, stateG2, stateG3 of the paper), n masters.
- ``cinderella``: the bucket game of Bodlaender et al. (as in slugs' benchmark generator):
  n buckets of capacity b, the stepmother adds at most s per step, Cinderella empties c
  adjacent (cyclically) buckets; she must never let a bucket overflow (a safety game).
- ``factory``: an assembly line with two arms (slugs' factory benchmark): a belt of length l
  carries items needing t tasks each; the arms must finish all tasks before an item leaves.
- ``moving_obstacle``: a robot on an n x n grid evading a 2x2 obstacle that moves unless
  the robot lets it glitch (slugs' moving obstacle benchmark).
- ``evasion``: slugs' EvasionOnGrid scene scaled: a w x h grid with static walls, a moving
  obstacle, and two delivery points the robot must visit in turn.
- ``genbuf``: the generalized buffer after Bloem et al., JCSS 2012, Sect. 7.1 (written from
  the paper's description): ``senders`` senders hand data over by a four-phase handshake
  (StoB_REQ / BtoS_ACK), the buffer stores it in a FIFO (ENQ / DEQ, FULL / EMPTY from the FIFO)
  and hands it to two receivers (BtoR_REQ / RtoB_ACK); every handshake completes. The
  unrealizable variant drops the receivers' fairness (a receiver may never acknowledge), so
  the FIFO may stay full while a sender waits.
- ``gridworld``: a robot on a w x h grid must visit k goal regions infinitely often while a
  patrolling adversary walks the middle row; one goal lies on that row. Realizable: the
  adversary must reach both ends of its row infinitely often (it patrols); unrealizable: it
  may stop anywhere, e.g. on the goal.
- ``arbiter``: a fair arbiter after Piterman, Pnueli, Sa'ar, "Synthesis of Reactive(1)
  Designs", VMCAI 2006 (written from the paper's description): n clients raise requests
  (inputs) and the arbiter answers with grants (outputs) by a handshake: a request changes
  only while it is answered, a grant only while its request is pending; at most one grant at
  a time, and every request and every release is eventually answered. Realizable: a granted
  client eventually releases; unrealizable: that assumption dropped (a client may keep the
  grant, so another client's request waits forever).
- ``lift``: an elevator over n floors: each floor's call button is an input that stays
  pressed until the lift stands at that floor, the lift (an output) moves at most one floor a
  step and stands still while its door is held open (an input); every call is eventually
  served. Realizable: the door is released infinitely often; unrealizable: that assumption
  dropped (the door may stay held while another floor calls).
"""

from __future__ import annotations


def amba(masters: int) -> str:
    """AMBA AHB arbiter with ``masters`` masters (JCSS 2012 Sect. 7.2)."""
    n = masters
    last = n - 1
    grants = [f'hgrant{i}' for i in range(n)]
    lines = {'INPUT': ['hready', 'hburst:0...2'] + [f'hbusreq{i}' for i in range(n)]
             + [f'hlock{i}' for i in range(n)],
             'OUTPUT': [f'hmaster:0...{max(last, 1)}', 'hmastlock', 'start', 'decide', 'locked',
                        'busreq', 'stateA1', 'stateG2', 'stateG3:0...3'] + grants}
    single, burst4, incr = 0, 1, 2
    # A4: everything starts low; A3: a lock request comes with a bus request.
    lines['ENV_INIT'] = ['!hready', f'hburst = {single}'] + [f'!hbusreq{i}' for i in range(n)] \
        + [f'!hlock{i}' for i in range(n)]
    lines['ENV_TRANS'] = [f"hlock{i}' -> hbusreq{i}'" for i in range(n)]
    # A2: the slave is ready infinitely often; A1 (a locked incremental burst ends), by the
    # monitor stateA1 the arbiter keeps.
    lines['ENV_LIVENESS'] = ['hready', '!stateA1']
    lines['SYS_INIT'] = ['hmaster = 0', '!hmastlock', 'start', 'decide', '!locked', '!busreq',
                         '!stateA1', '!stateG2', 'stateG3 = 0', 'hgrant0'] \
        + [f'!{g}' for g in grants[1:]]
    trans = []
    # BUSREQ = HBUSREQ[HMASTER]
    trans += [f"hmaster' = {i} -> (busreq' <-> hbusreq{i}')" for i in range(n)]
    trans.append(f"hmaster' <= {last}")
    # Monitor of A1: set by a locked incremental burst, kept while the master requests.
    trans.append(f"stateA1' <-> (!stateA1 & hmastlock & hburst = {incr} | stateA1 & busreq)")
    # G1: a new transfer starts only when the slave is ready.
    trans.append("!hready -> !start'")
    # G2: a locked incremental burst is not interrupted while the master requests the bus.
    trans.append(f"stateG2' <-> (!stateG2 & hmastlock & hburst = {incr} & start"
                 " | stateG2 & !start & busreq)")
    trans.append('!(stateG2 & start)')
    # G3: a locked BURST4 is not interrupted for three more ready cycles.
    trans.append(f"stateG3 = 0 & hmastlock & hburst = {burst4} & start & hready -> stateG3' = 1")
    trans.append(f"stateG3 = 0 & !(hmastlock & hburst = {burst4} & start & hready) -> stateG3' = 0")
    trans += [f"stateG3 = {k} & hready -> stateG3' = {(k + 1) % 4}" for k in (1, 2, 3)]
    trans += [f"stateG3 = {k} & !hready -> stateG3' = {k}" for k in (1, 2, 3)]
    trans.append('stateG3 != 0 -> !start')
    for i in range(n):
        # G4: a grant takes effect when the slave is ready; G7: the lock follows the request.
        trans.append(f"hready -> (hgrant{i} <-> hmaster' = {i})")
        trans.append(f"decide & hgrant{i}' -> (hlock{i} <-> locked')")
        if i > 0:  # G10: no grant to a master that has not requested
            trans.append(f"!hgrant{i} & !hbusreq{i} -> (!hgrant{i}' | hbusreq{i}')")
    # G5: the lock takes effect with the grant; G6: master and lock change only at a start.
    trans.append("hready -> (locked <-> hmastlock')")
    trans.append("!start' -> (hmaster' = hmaster & (hmastlock' <-> hmastlock))")
    # G8: grants and lock change only when the arbiter decides.
    trans.append("!decide -> (" + ' & '.join(f"(hgrant{i}' <-> hgrant{i})" for i in range(n))
                 + " & (locked' <-> locked))")
    # G10: with no requests, the default master 0 is granted.
    trans.append('decide & ' + ' & '.join(f'!hbusreq{i}' for i in range(n)) + " -> hgrant0'")
    # Exactly one grant.
    trans.append(' | '.join(f"{g}'" for g in grants))
    trans += [f"!{a}' | !{b}'" for k, a in enumerate(grants) for b in grants[k + 1:]]
    lines['SYS_TRANS'] = trans
    # G2's fairness, G9: every request is eventually served (or withdrawn).
    lines['SYS_LIVENESS'] = ['!stateG2'] + [f'!hbusreq{i} | hmaster = {i}' for i in range(n)]
    return _text(lines)


def cinderella(buckets: int, adjacent: int, capacity: int, power: int) -> str:
    """Cinderella-stepmother game: ``buckets`` buckets of ``capacity``, Cinderella empties
    ``adjacent`` consecutive ones (cyclically) per step, the stepmother adds ``power`` in all."""
    emptied = []
    for i in range(buckets):
        # Bucket i is emptied by choice e when it is one of e, e+1, ..., e+adjacent-1 (mod n).
        emptied.append(f'((e <= {i} & e+{adjacent} > {i}) | (e+{adjacent - 1} >= {i + buckets}))')
    lines = {'INPUT': [f'x{i}:0...{power}' for i in range(buckets)],
             'OUTPUT': [f'y{i}:0...{capacity}' for i in range(buckets)] + [f'e:0...{buckets - 1}'],
             'ENV_TRANS': [_sum_at_most([f"x{i}'" for i in range(buckets)], power)],
             'ENV_INIT': [f'x{i} = 0' for i in range(buckets)],
             'SYS_INIT': [f'y{i} = 0' for i in range(buckets)],
             'SYS_TRANS': [f"!{emptied[i]} -> y{i}' = y{i} + x{i}'" for i in range(buckets)]
             + [f"{emptied[i]} -> y{i}' = x{i}'" for i in range(buckets)]}
    return _text(lines)


def factory(length: int, tasks: int, steps: int, errors: int) -> str:
    """Assembly line: a belt of ``length`` positions, ``tasks`` tasks per item, the belt moves
    every ``steps`` steps, the environment may break up to ``errors`` items."""
    positions = [f'p{i}_{j}' for i in range(length) for j in range(tasks)]
    env_trans = [
        "movingcounter'=0 -> ((" + ' | '.join(f"p0_{j}'" for j in range(tasks))
        + ") | errorCount' > errorCount)",
        "errorCount' >= errorCount"]
    env_trans += [f"movingcounter'!=0 -> (p0_{j}' <-> p0_{j} & (movingcounter'!=0)"
                  f" | arm1=0 & arm1op={j} | arm2=0 & arm2op={j})" for j in range(tasks)]
    env_trans += [f"p{i}_{j}' <-> (p{i}_{j} & (movingcounter'!=0) | arm1={i} & arm1op={j}"
                  f" | arm2={i} & arm2op={j} | (p{i - 1}_{j} & movingcounter'=0))"
                  for i in range(1, length) for j in range(tasks)]
    env_trans += [f"(movingcounter<{steps - 1}) -> (movingcounter' = movingcounter+1)",
                  f"(movingcounter={steps - 1}) -> (movingcounter' = 0)"]
    lines = {'INPUT': [f'movingcounter:0...{steps - 1}'] + positions + [f'errorCount:0...{errors}'],
             'OUTPUT': [f'arm1:0...{length - 1}', f'arm2:0...{length - 1}',
                        f'arm1op:0...{tasks - 1}', f'arm2op:0...{tasks - 1}'],
             'ENV_TRANS': env_trans,
             'SYS_TRANS': ["arm1' < arm2'", "arm1' <= arm1+1", "arm1 <= arm1'+1",
                           "arm2' <= arm2+1", "arm2 <= arm2'+1"]
             + [f"!(!p{length - 1}_{j} & movingcounter'=0)" for j in range(tasks)],
             'ENV_INIT': ['movingcounter = 0'] + positions,
             'SYS_INIT': ['arm1 = 0', 'arm2 = 2', 'arm1op = 0', 'arm2op = 0']}
    return _text(lines)


def moving_obstacle(size: int, glitches: int) -> str:
    """A robot on a ``size`` x ``size`` grid evades a moving 2x2 obstacle (``glitches`` times
    the obstacle may move although the robot said it must not)."""
    top = size - 1
    lines = {
        'INPUT': [f'obsx: 0...{top - 1}', f'obsy: 0...{top - 1}', f'robx: 0...{top}',
                  f'roby: 0...{top}', f'glitches: 0...{glitches}'],
        'OUTPUT': ['movx: 0...2', 'movy: 0...2', 'obsmove'],
        'SYS_INIT': ['! obsmove'],
        'SYS_TRANS': ['(robx < obsx) | (robx >= obsx+2) | (roby < obsy) | (roby >= obsy+2)',
                      "(obsmove' -> ( (obsx=obsx') & (obsy=obsy') ) )",
                      "((! obsmove') -> ! ( (obsx=obsx') & (obsy=obsy') ) )"],
        'ENV_INIT': ['robx = 0', 'roby = 0', f'obsx = {top - 1}', f'obsy = {top - 1}', 'glitches = 0'],
        'ENV_TRANS': [
            "(obsx' <= obsx+1) & (obsy' <= obsy+1) & (obsx <= obsx'+1) & (obsy <= obsy'+1)"
            " & (robx' <= robx+1) & (roby' <= roby+1) & (robx <= robx'+1) & (roby <= roby'+1)",
            f"(robx=0 & robx'=0 & movx<=1 | robx'+1 <= robx+movx) & (robx={top} & robx'={top}"
            f" & movx >= 1 | robx'+1 >= robx+movx) & (roby=0 & roby'=0 & movy <= 1 | roby'+1 <= "
            f"roby+movy) & (roby={top} & roby'={top} & movy>=1 | roby'+1 >= roby+movy)",
            "glitches' >= glitches",
            "(obsmove | (obsx=obsx')) & (obsmove | (obsy=obsy')) | (glitches' >= glitches+1)"]}
    return _text(lines)


def evasion(width: int, height: int) -> str:
    """slugs' EvasionOnGrid scene on a ``width`` x ``height`` grid (walls and delivery points
    placed at the same relative positions as in its 24 x 8 example)."""
    def sx(x):  # scale an x coordinate of the 24-wide original
        return min(width - 1, round(x * width / 24))

    def sy(y):
        return min(height - 1, round(y * height / 8))
    w, h = width - 1, height - 1
    pickup = (sx(9), sx(10), sy(3), sy(4))
    drop = (sx(13), sx(14), sy(3), sy(4))
    lines = {
        'INPUT': [f'x:0...{w}', f'y:0...{h}', f'mox:0...{w}', f'moy:0...{h}',
                  'deliveryrequest', 'door'],
        'OUTPUT': ['left', 'right', 'up', 'down', 'pickup', 'drop',
                   'requestPending1', 'requestPending2'],
        'ENV_INIT': ['x = 0', 'y = 0', f'mox = {sx(16)}', f'moy = {sy(6)}', '! deliveryrequest'],
        'SYS_INIT': ['! left', '! right', '! up', '! down', '! pickup', '! drop'],
        'ENV_TRANS': [
            "x>0 & left -> x'+1=x", f"x<{w} & right -> x'=x+1", "y>0 & up -> y'+1=y",
            f"y<{h} & down -> y'=y+1", "(!left & !right) -> x'=x", "(!up & !down) -> y'=y",
            "mox' <= mox+1", "moy' <= moy+1", "mox <= mox'+1", "moy <= moy'+1",
            "mox'=mox | moy'=moy",
            f"mox'<{sx(3)} | mox'>{sx(19)} | (moy'!={sy(2)} & moy'!={sy(1)})",
            f"mox'<{sx(3)} | mox'>{sx(19)} | (moy'!={sy(5)} & moy'!={sy(4)})",
            f"mox'<{sx(10)} | mox'>{sx(12)} | moy'<{sy(2)} | moy'>{sy(4)}",
            f"moy'<{h}"],
        'SYS_TRANS': [
            "! left' | ! right'", "! up' | ! down'", "! pickup' | ! drop'",
            f"x<{sx(4)} | x>{sx(19)} | y!={sy(2)}", f"x<{sx(4)} | x>{sx(19)} | y!={sy(5)}",
            f"x<{sx(11)} | x>{sx(12)} | y<{sy(3)} | y>{sy(4)}",
            # Never touch the moving obstacle.
            "x' != mox' | y' != moy'", "x' != mox | y' != moy",
            _at(pickup) + " -> ! requestPending1'",
            f"!{_at(pickup)} -> (requestPending1' <-> (requestPending1 | deliveryrequest))",
            _at(drop) + " -> ! requestPending2'",
            f"!{_at(drop)} -> (requestPending2' <-> (requestPending2 | requestPending1))"],
        'SYS_LIVENESS': ['!requestPending1', '!requestPending2']}
    return _text(lines)


def genbuf(senders: int, realizable: bool = True) -> str:
    """Generalized buffer of ``senders`` senders and two receivers (JCSS 2012 Sect. 7.1)."""
    receivers = 2
    requests = [f'sreq{i}' for i in range(senders)]
    acks = [f'sack{i}' for i in range(senders)]
    rreqs = [f'rreq{j}' for j in range(receivers)]
    racks = [f'rack{j}' for j in range(receivers)]
    lines = {'INPUT': requests + racks + ['full', 'empty'],
             'OUTPUT': acks + rreqs + ['enq', 'deq', f'slc:0...{max(senders - 1, 1)}']}
    lines['ENV_INIT'] = [f'!{r}' for r in requests + racks] + ['empty', '!full']
    env_trans = []
    for req, ack in zip(requests, acks):
        # A sender keeps its request until acknowledged, then lowers it.
        env_trans += [f"{req} & !{ack} -> {req}'", f"{ack} -> !{req}'"]
    for rreq, rack in zip(rreqs, racks):
        # A receiver acknowledges only a request, and keeps its acknowledgement while requested.
        env_trans += [f"!{rreq} -> !{rack}'", f"{rreq} & {rack} -> {rack}'"]
    # The FIFO: an enqueue makes it non-empty, a dequeue non-full; idle, it keeps its flags.
    env_trans += ["enq & !deq -> !empty'", "deq & !enq -> !full'",
                  "!enq & !deq -> ((full' <-> full) & (empty' <-> empty))", "!(full' & empty')"]
    lines['ENV_TRANS'] = env_trans
    lines['ENV_LIVENESS'] = [f'{rreq} <-> {rack}' for rreq, rack in zip(rreqs, racks)] \
        if realizable else []
    lines['SYS_INIT'] = [f'!{a}' for a in acks + rreqs] + ['!enq', '!deq']
    sys_trans = []
    for index, (req, ack) in enumerate(zip(requests, acks)):
        # No acknowledgement without a request; kept while requested; a new one enqueues the
        # sender's data (slc selects the sender).
        sys_trans += [f"!{req} -> !{ack}'", f"{req} & {ack} -> {ack}'",
                      f"!{ack} & {ack}' -> (enq' & slc' = {index})"]
    sys_trans.append("enq' -> (" + ' | '.join(f'(!{a} & {a}\')' for a in acks) + ')')
    sys_trans += [f"!{a}' | !{b}'" for k, a in enumerate(acks) for b in acks[k + 1:]]
    for rreq, rack in zip(rreqs, racks):
        # A request to a receiver is kept until acknowledged, then lowered; a new one dequeues.
        sys_trans += [f"{rreq} & !{rack} -> {rreq}'", f"{rack} -> !{rreq}'",
                      f"!{rreq} & {rreq}' -> deq'"]
    sys_trans.append("deq' -> (" + ' | '.join(f"(!{r} & {r}')" for r in rreqs) + ')')
    sys_trans += [f"!{rreqs[0]}' | !{rreqs[1]}'", "full' -> !enq'", "empty' -> !deq'"]
    lines['SYS_TRANS'] = sys_trans
    # Every sender's handshake completes infinitely often; so does every receiver's.
    lines['SYS_LIVENESS'] = [f'{req} <-> {ack}' for req, ack in zip(requests, acks)] \
        + [f'{rreq} <-> {rack}' for rreq, rack in zip(rreqs, racks)]
    return _text(lines)


def gridworld(width: int, height: int, goals: int, realizable: bool = True) -> str:
    """A robot visits ``goals`` regions of a ``width`` x ``height`` grid infinitely often; an
    adversary patrols the middle row (it must reach both of its ends infinitely often when
    ``realizable``). The robot never shares a cell with the adversary nor swaps with it."""
    row = height // 2
    regions = _goal_regions(width, height, row, goals)
    lines = {'INPUT': [f'ax:0...{width - 1}'],
             'OUTPUT': [f'x:0...{width - 1}', f'y:0...{height - 1}'],
             'ENV_INIT': ['ax = 0'],
             'SYS_INIT': [f'x = {width - 1}', 'y = 0'],
             'ENV_TRANS': ["ax' <= ax+1 & ax <= ax'+1"],
             'SYS_TRANS': ["x' <= x+1 & x <= x'+1 & y' <= y+1 & y <= y'+1 & (x' = x | y' = y)",
                           f"y' != {row} | x' != ax'", f"y' != {row} | x' != ax"],
             'ENV_LIVENESS': ['ax = 0', f'ax = {width - 1}'] if realizable else [],
             'SYS_LIVENESS': [_at(region) for region in regions]}
    return _text(lines)


def arbiter(clients: int, realizable: bool = True) -> str:
    """Fair arbiter of ``clients`` clients (VMCAI 2006): requests ``r<i>`` in, grants
    ``g<i>`` out, four-phase handshake per client, mutually exclusive grants."""
    requests = [f'r{i}' for i in range(clients)]
    grants = [f'g{i}' for i in range(clients)]
    pairs = list(zip(requests, grants))
    lines = {'INPUT': requests, 'OUTPUT': grants,
             'ENV_INIT': [f'!{r}' for r in requests],
             'SYS_INIT': [f'!{g}' for g in grants],
             # A client changes its request only once the arbiter has answered the last one.
             'ENV_TRANS': [f"!({r} <-> {g}) -> ({r}' <-> {r})" for r, g in pairs],
             # The arbiter changes a grant only to answer a pending request or release; at
             # most one grant at a time.
             'SYS_TRANS': [f"({r} <-> {g}) -> ({g}' <-> {g})" for r, g in pairs]
             + [f"!{a}' | !{b}'" for k, a in enumerate(grants) for b in grants[k + 1:]],
             # A granted client eventually releases (dropped in the unrealizable variant).
             'ENV_LIVENESS': [f'!({r} & {g})' for r, g in pairs] if realizable else [],
             # Every request and every release is eventually answered.
             'SYS_LIVENESS': [f'{r} <-> {g}' for r, g in pairs]}
    return _text(lines)


def lift(floors: int, realizable: bool = True) -> str:
    """An elevator over ``floors`` floors: call buttons ``b<i>`` and the door ``hold`` in,
    the lift's ``floor`` out; every call is eventually served."""
    buttons = [f'b{i}' for i in range(floors)]
    env_trans = []
    for index, button in enumerate(buttons):
        # A call stays until the lift stands at its floor, which clears it.
        env_trans += [f"{button} & floor != {index} -> {button}'",
                      f"{button} & floor = {index} -> !{button}'"]
    lines = {'INPUT': buttons + ['hold'], 'OUTPUT': [f'floor:0...{floors - 1}'],
             'ENV_INIT': [f'!{b}' for b in buttons] + ['!hold'],
             'SYS_INIT': ['floor = 0'],
             'ENV_TRANS': env_trans,
             # One floor a step at most; standing still while the door is held open.
             'SYS_TRANS': ["floor' <= floor+1 & floor <= floor'+1", "hold -> floor' = floor"],
             # The door is released infinitely often (dropped in the unrealizable variant).
             'ENV_LIVENESS': ['!hold'] if realizable else [],
             'SYS_LIVENESS': [f'!{b}' for b in buttons]}
    return _text(lines)


def _goal_regions(width: int, height: int, row: int, goals: int) -> list:
    """``goals`` boxes (x0, x1, y0, y1): 2x2 squares spread over the grid, alternately above
    and below the adversary's row, and one cell on that row."""
    regions = []
    for index in range(goals - 1):
        x0 = min(width - 2, round(index * (width - 2) / max(goals - 2, 1)))
        y0 = 0 if index % 2 == 0 else height - 2
        regions.append((x0, x0 + 1, y0, y0 + 1))
    middle = width // 2
    regions.append((middle, middle, row, row))
    return regions


def _sum_at_most(terms: list[str], bound: int) -> str:
    """``t0+t1+... <= bound`` split into halves (each half's partial sum enumerated), so that
    no single comparison ranges over too many valuations for the parser."""
    if len(terms) <= 3:
        return '(' + '+'.join(terms) + f' <= {bound})'
    left, right = terms[:len(terms) // 2], terms[len(terms) // 2:]
    return '(' + ' | '.join(f"({_sum_equals(left, value)} & {_sum_at_most(right, bound - value)})"
                            for value in range(bound + 1)) + ')'


def _sum_equals(terms: list[str], value: int) -> str:
    if len(terms) <= 3:
        return '(' + '+'.join(terms) + f' = {value})'
    left, right = terms[:len(terms) // 2], terms[len(terms) // 2:]
    return '(' + ' | '.join(f"({_sum_equals(left, part)} & {_sum_equals(right, value - part)})"
                            for part in range(value + 1)) + ')'


def _at(box) -> str:
    x0, x1, y0, y1 = box
    return f'((x>={x0} & x<={x1}) & (y>={y0} & y<={y1}))'


SECTION_ORDER = ['INPUT', 'OUTPUT', 'ENV_INIT', 'SYS_INIT', 'ENV_TRANS', 'SYS_TRANS',
                 'ENV_LIVENESS', 'SYS_LIVENESS']


def _text(lines: dict) -> str:
    return ''.join(f'[{section}]\n' + ''.join(f'{line}\n' for line in lines[section]) + '\n'
                   for section in SECTION_ORDER if section in lines)


GRIDWORLD_SIZES = [(7, 5, 3), (10, 8, 4), (13, 10, 6), (16, 13, 7), (19, 16, 8), (25, 20, 10),
                   (32, 24, 12), (48, 32, 14), (64, 48, 16)]

# (name, size label, generator arguments), smallest first within each family.
FAMILIES = {
    'amba': [(f'{n} masters', amba, (n,)) for n in range(2, 11)],
    'cinderella': [(f'n{n}c{c} b{b} s{s}', cinderella, (n, c, b, s)) for n, c, b, s in [
        (5, 2, 6, 4), (5, 2, 7, 4), (5, 3, 12, 9), (6, 3, 10, 6), (6, 3, 11, 6), (6, 2, 13, 6),
        (6, 2, 14, 6), (6, 1, 15, 5), (7, 3, 13, 7), (7, 1, 20, 6), (8, 3, 15, 8), (7, 1, 33, 10),
        (10, 3, 15, 8)]],
    'factory': [(f'{n}x{t} s{s} e{e}', factory, (n, t, s, e)) for n, t, s, e in [
        (3, 3, 1, 1), (4, 3, 1, 1), (5, 3, 1, 0), (5, 4, 1, 0), (5, 5, 2, 0), (5, 5, 2, 1),
        (7, 3, 1, 0), (7, 5, 2, 0), (7, 5, 2, 10), (9, 5, 2, 10), (11, 6, 2, 12)]],
    'moving_obstacle': [(f'{n}x{n} g{g}', moving_obstacle, (n, g)) for n, g in [
        (8, 0), (8, 1), (16, 3), (16, 4), (24, 7), (24, 8), (32, 11), (32, 12), (40, 15), (40, 16),
        (48, 19), (64, 27), (96, 43), (128, 60)]],
    'evasion': [(f'{w}x{h}', evasion, (w, h)) for w, h in [
        (24, 8), (48, 16), (64, 24), (96, 32), (128, 64), (256, 128), (512, 256)]],
    'genbuf': [(f'{n} senders', genbuf, (n, True)) for n in (4, 8, 16, 24, 32, 48, 64)],
    'genbuf_unrealizable': [(f'{n} senders', genbuf, (n, False)) for n in (4, 8, 16, 24, 32, 48, 64)],
    'gridworld': [(f'{w}x{h} k={k}', gridworld, (w, h, k, True)) for w, h, k in GRIDWORLD_SIZES],
    'gridworld_unrealizable': [(f'{w}x{h} k={k}', gridworld, (w, h, k, False))
                               for w, h, k in GRIDWORLD_SIZES],
    'arbiter': [(f'{n} clients', arbiter, (n, True)) for n in (4, 8, 16, 24, 32, 48, 64)],
    'arbiter_unrealizable': [(f'{n} clients', arbiter, (n, False))
                             for n in (4, 8, 16, 24, 32, 48, 64, 96)],
    'lift': [(f'{n} floors', lift, (n, True)) for n in (8, 16, 32, 48, 64, 96, 128)],
    'lift_unrealizable': [(f'{n} floors', lift, (n, False)) for n in (8, 16, 32, 48, 64, 96, 128)],
}


def free_inputs(width: int) -> str:
    """``width`` free inputs and ``width`` outputs, each output following the previous one and
    its input (a shift register of parities), and an environment liveness that never holds:
    every position wins, and an explicit strategy answers all 2^width inputs at every state
    (the case of a specification whose assumptions contradict: 10^4-10^6 strategy edges)."""
    lines = {'INPUT': [f'x{i}' for i in range(width)],
             'OUTPUT': [f'y{i}' for i in range(width)],
             'SYS_TRANS': ["y0' <-> x0'"] + [f"y{i}' <-> (y{i - 1} ^ x{i}')" for i in range(1, width)],
             'ENV_LIVENESS': ['x0 & !x0'],
             'SYS_LIVENESS': [f'y{width - 1}', f'!y{width - 1} | x0']}
    return _text(lines)
