"""The connection's request counts (stCBT_Connection.Queued, Waiting and QueueDepth) are kept by CBTi_SetSlot at every
slot change instead of being recounted each scan; they must equal a recount of the 16 slots in every state the
table goes through: filled, sent, waiting for tags, replaced by a new edge (R5), aborted by a stop, timed out,
ended by a link loss and by a reconnect."""
from rig import Rig

PENDING = ("SlotQueued", "SlotSent", "SlotWaitTag")


def assert_counts_match(r, when):
    names = [r.read(f"Cobot.Req[{s}].State") for s in range(1, 17)]
    counts = (names.count("SlotQueued"), names.count("SlotWaitTag"), sum(1 for n in names if n in PENDING))
    kept = (r.read("Cobot.Queued"), r.read("Cobot.Waiting"), r.read("Cobot.QueueDepth"))
    assert kept == counts, (when, names)
    depth = counts[2]
    return depth


def test_counts_equal_a_recount_through_fill_tags_retrigger_timeout_loss_and_reconnect():
    r = Rig(program="Main_Many.st")
    try:
        assert assert_counts_match(r, "idle") == 0
        for k in range(1, 17):                       # 15 non-blended motions take the 15 tags, one waits queued
            r.write(f"Exec[{k}]", True)
        r.scans(2)
        assert assert_counts_match(r, "filled") == 16 and r.read("Cobot.Queued") == 1
        r.write("Exec[16]", False)                   # a new edge replaces the queued one (R5)
        r.scans(1)
        r.write("Exec[16]", True)
        r.scans(1)
        assert_counts_match(r, "re-triggered while queued")
        assert r.until(lambda: r.read("mv[1].Done"), 10)
        assert_counts_match(r, "first motion done")
        for k in range(1, 17):
            r.write(f"Exec[{k}]", False)
        r.scans(1)
        assert_counts_match(r, "Execute released while motions run")
        r.robot.inject("black_hole")                 # no more replies: what is sent times out
        r.write("Blend", True)
        r.write("Exec[17]", True)
        r.scans(2)
        assert_counts_match(r, "blended motion sent into the black hole")
        r.until(lambda: r.read("mv[17].Error"), 10)
        assert_counts_match(r, "reply timeout")
        r.write("ConnExec", False)                   # close: everything pending ends (CBTi_FailAll)
        r.scans(3)
        assert assert_counts_match(r, "closed") == 0
        r.robot.clear_faults()
        r.write("ConnExec", True)
        assert r.until(lambda: r.read("conn.Connected"), 10)
        r.write("Exec[17]", False)
        r.scans(1)
        r.write("Exec[17]", True)
        assert r.until(lambda: r.read("mv[17].Done"), 10)
        r.scans(1)
        assert assert_counts_match(r, "reconnected and done") == 0
    finally:
        r.close()
