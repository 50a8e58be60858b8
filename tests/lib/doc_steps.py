"""The example of every FB page in docs/library/, as steps: the BOOL inputs the example raises one after the
other once connected, and the output that ends each step. test_lib_doc_examples.py runs the examples with them,
test_lib_doc_traces.py draws their timing diagrams."""

# page -> (BOOL inputs raised one after the other once connected, output that ends each step)
STEPS = {
    "CBT_Connect": [("ConnectSwitch", "RobotReady")],
    "CBT_MoveAbsolute": [("MoveAbsExec", "fbMoveAbs.Done")],
    "CBT_MoveRelative": [("MoveRelExec", "fbMoveRel.Done")],
    "CBT_MoveCircle": [("MoveCircleExec", "fbMoveCircle.Done")],
    "CBT_ChangeBase": [("ChangeBaseExec", "fbChangeBase.Done")],
    "CBT_ChangeTCP": [("ChangeTCPExec", "fbChangeTCP.Done")],
    "CBT_ProgramControl": [("PauseButton", "fbPause.Done"), ("ResumeButton", "fbResume.Done")],
    "CBT_Stop": [("StopButton", "fbStop.Done")],
    "CBT_SetOutput": [("CloseGripper", "fbGripper.Done")],
    "CBT_ReadActualPosition": [(None, "fbReadPos.Valid")],
    "CBT_RobotStatus": [(None, "fbStatus.Valid")],
    "CBT_ProjectControl": [("PlayButton", "fbPlay.Done")],
    "CBT_ReadIO": [(None, "fbIO.Valid")],
    "CBT_SetOverride": [("SlowButton", "fbOverride.Done")],
    "CBT_WaitQueue": [("MoveExec", "fbMove.Done"), ("SyncExec", "fbSync.Done")],
    "CBT_ReadVariable": [("ReadExec", "fbRead.Done")],
    "CBT_WriteVariable": [("WriteExec", "fbWrite.Done")],
    "CBT_Jog": [("JogPlusButton", "fbJog.Active")],
    "CBT_Teach": [("TeachButton", "fbTeach.Done")],
    "CBT_VisionJob": [("CameraButton", "fbVision.Done"), ("PickButton", "fbApproach.Done")],
}
