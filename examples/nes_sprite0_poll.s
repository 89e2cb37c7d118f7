; Wait for the NES sprite-zero hit the way a game does: poll $2002 until bit 6 (the hit flag) is set.
; BIT copies bit 6 of the byte it reads into V, so BVC loops while the flag is still clear.
;
;   retro run examples/nes_sprite0_poll.s --entry wait --scene examples/nes_sprite0.toml
;
; The run's cycle count, minus the cycles after the read that saw the flag (BVC not taken: 2, RTS: 6,
; and the BIT's read is its last cycle: 1), is the CPU cycle of that read, counted from the frame start.

        .org $c000
wait:   bit $2002
        bvc wait
        rts
