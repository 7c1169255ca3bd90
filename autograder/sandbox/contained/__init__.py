"""What runs in the contained program's own process: the launcher that contains a student's
program and ``exec``s it (:mod:`.launcher`), the program's start (:mod:`.runner`), and the
warm start that does both in a process forked from a prepared one (:mod:`.zygote`, which
also holds the pytest child's end of its socket)."""
