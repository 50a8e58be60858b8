"""Omron Sysmac names vplc does not model: instructions (W502), motion instructions (W507/W508) and system-defined
variables (W501), each with the manual and the section where it is described — names and references only.

A name used in a program that is neither declared nor modelled by vplc is reported as a real Omron name that vplc
does not model (ST1007), not as a misspelt variable (ST1001). Names the prelude declares (prelude/*.st) are
found before this table is consulted, so an instruction that becomes modelled (the motion instructions the motion
prelude declares) needs no change here (tests/vplc/frontend/test_fe_sysmac_names.py).
"""
from __future__ import annotations

_W502_SECTIONS: dict[str, tuple[str, ...]] = {
    "Data Type Conversion Instructions": ("NumToEnum", "NumToDecString", "NumToHexString"),
    "Math Instructions": ("CheckReal",),
    "Array Data Instructions": ("ArySearch", "AryCmpEQ", "AryCmpNE", "AryCmpLT", "AryCmpLE", "AryCmpGT",
                                "AryCmpGE", "AryMax", "AryMin", "AryMean", "ArySD", "AryAdd", "ArySub",
                                "AryExchg"),
    "Control Instructions": ("PIDAT_HeatCool",),
    "System Control Instructions": ("ResetCJBError", "GetCJBError", "GetEIPError", "ResetEIPError",
                                    "GetMyTaskStatus", "Task_IsActive", "ActEventTask", "TraceSamp", "TraceTrig",
                                    "Lock", "Unlock"),
    "EtherCAT Communications Instructions": ("EC_CoESDOWrite", "EC_CoESDORead", "EC_StartMon", "EC_StopMon",
                                              "EC_SaveMon", "EC_CopyMon", "EC_DisconnectSlave",
                                              "EC_ConnectSlave"),
    "Socket Service Instructions": ("SktUDPCreate", "SktUDPSend", "SktUDPRcv", "SktSetOption"),
    "SD Memory Card Instructions": ("FileWriteVar", "FileReadVar", "FileOpen", "FileClose", "FileRead",
                                    "FileWrite", "FileRemove", "FileRename", "FileCopy", "DirCreate", "DirRemove"),
    "Serial Communications Instructions": ("SerialSend", "SerialRcv", "SendCmd", "ExecPMCR"),
    "NX Unit Instructions": ("NX_WriteObj", "NX_ReadObj"),
}

_W508_MOTION = ("MC_Power", "MC_Home", "MC_HomeWithParameter", "MC_Move", "MC_MoveAbsolute", "MC_MoveRelative",
                "MC_MoveVelocity", "MC_MoveFeed", "MC_MoveZeroPosition", "MC_MoveJog", "MC_Stop",
                "MC_ImmediateStop", "MC_Reset", "MC_ReadAxisError", "MC_SetPosition", "MC_SetOverride",
                "MC_ChangeAxisUse", "MC_TorqueControl", "MC_SetTorqueLimit", "MC_ZoneSwitch", "MC_TouchProbe",
                "MC_AbortTrigger", "MC_CamIn", "MC_CamOut", "MC_GearIn", "MC_GearOut", "MC_GearInPos",
                "MC_MoveLink", "MC_CombineAxes", "MC_Phasing", "MC_SyncMoveVelocity", "MC_DigitalCamSwitch",
                "MC_GroupEnable", "MC_GroupDisable", "MC_GroupStop", "MC_GroupReset", "MC_GroupImmediateStop",
                "MC_MoveLinear", "MC_MoveLinearAbsolute", "MC_MoveLinearRelative", "MC_MoveCircular2D",
                "MC_ReadGroupError", "MC_Write", "MC_ReadStatus")

_W501_SYSVARS = ("_EIP_EtnCommErr", "_EIP_PortErr", "_EIP_IPAdrCfgErr", "_EC_ErrSta", "_EC_PortErr",
                 "_EC_CommErrTbl", "_EC_PDSlavTbl", "_EC_MBXSlavTbl", "_MC_ErrSta", "_PLC_ErrSta", "_CJB_ErrSta",
                 "_AlarmFlag", "_RetainFail", "_MC_AX", "_MC_GRP", "_MC_COM")

SYSMAC_NAMES: dict[str, tuple[str, str]] = {}
for _section, _names in _W502_SECTIONS.items():
    for _n in _names:
        SYSMAC_NAMES[_n.upper()] = ("instruction", f"W502, {_section}")
for _n in _W508_MOTION:
    SYSMAC_NAMES.setdefault(_n.upper(), ("motion instruction", "W508"))
for _n in _W501_SYSVARS:
    SYSMAC_NAMES.setdefault(_n.upper(), ("system-defined variable", "W501, system-defined variables"))


def describe(name: str) -> str | None:
    """``Sysmac instruction `X` (W502, ...)`` for an Omron name vplc does not model, else None."""
    hit = SYSMAC_NAMES.get(name.rsplit("\\", 1)[-1].upper())
    if hit is None:
        return None
    kind, where = hit
    return f"Sysmac {kind} `{name}` ({where}) is not modelled by vplc"
