
R/
robin-fuzz-make-corpusfieldsneumann_solve