.label m = $FB
        * = $C000
absdiff:
        sec
        sbc m
        bcs done
        eor #$FF
        adc #$01
done:
        rts
